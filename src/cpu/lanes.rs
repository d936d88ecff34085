//! The pair pass of the standard Hertz-Mindlin model (Hertz, restitution damping, Mindlin
//! tangential spring with one mu; no rolling or twisting: LAMMPS' and LIGGGHTS' default
//! granular model), with or without capillary bridges, in lanes that the compiler turns into
//! vector instructions.
//!
//! Each window of pairs is first tested for touch without a branch (the positions and radii
//! read one pair at a time, the fold and the test in vector lanes) and split into its touching
//! and open pairs. The open ones are done at once (a third of a dense packing's listed pairs,
//! most of a capillary scene's): dry, a zero force and forgotten springs; wet, `pair_force`
//! itself (springs forgotten, a bridge's pull across the gap). The touching ones, packed, load
//! the rest of their grains one pair at a time and run the very same `contact_force` as the
//! one-pair pass in every lane, with the laws fixed at compile time; a bridge adds its contact
//! force `f0` by a select. Same operations on the same inputs, so the same bits as
//! `pair_force`; `tests` below check it.

use crate::state::ForceContext;
use crate::state::PairList;
use crate::state::{Body, Props};
use crate::model::{at_edge, contact_force, Bodies, CohesionLaw, ContactForce, ContactModel, DampingLaw, Geometry, Hertz, History, Kinematics, NormalLaw, PairCoeffs, Regime, RollingLaw, TangentialLaw, TangentialStiffness, TwistingLaw, KickWindow};
use crate::position::{complete, residual_at};
use crate::real::{Real, Vec3};

/// Pairs per lane group: two AVX-512 vectors of f64, one of f32. A window's last group is
/// partly empty (a few hundred touching pairs per task); 32 lanes wasted twice as many and ran
/// about 5% slower (the bed, f64, one thread: mean of ten runs side by side, 1.05x for 16).
const LANES: usize = 16;
// A lane array of the narrowest real fills whole cache lines (see [`Inputs`]).
const _: () = assert!((LANES * std::mem::size_of::<f32>()).is_multiple_of(64));

/// `model` rebuilt with its laws as compile-time constants when it is the standard
/// Hertz-Mindlin model (with any cohesion), so that the composed `contact_force` folds to
/// straight-line code; the lanes add the cohesion themselves.
#[inline(always)]
pub fn hertz_mindlin<T: Real>(model: &ContactModel<T>) -> Option<ContactModel<T>> {
    let TangentialLaw::Mindlin { damping_ratio, .. } = model.tangential else { return None };
    let fixed = ContactModel {
        normal: NormalLaw::Hertz(Hertz),
        damping: DampingLaw::Restitution,
        tangential: TangentialLaw::Mindlin { damping_ratio, stiffness: TangentialStiffness::Mindlin },
        rolling: RollingLaw::None,
        twisting: TwistingLaw::None,
        cohesion: model.cohesion,
        limit_damping: model.limit_damping,
    };
    (*model == fixed).then_some(ContactModel { cohesion: CohesionLaw::None, ..fixed })
}

/// Three lanes of reals, one per component.
#[derive(Clone, Copy)]
#[repr(C, align(64))]
struct V3s<T> {
    x: [T; LANES],
    y: [T; LANES],
    z: [T; LANES],
}

impl<T: Real> V3s<T> {
    const ZERO: Self = V3s { x: [T::ZERO; LANES], y: [T::ZERO; LANES], z: [T::ZERO; LANES] };

    #[inline(always)]
    fn get(&self, m: usize) -> Vec3<T> {
        Vec3::new(self.x[m], self.y[m], self.z[m])
    }

    #[inline(always)]
    fn set(&mut self, m: usize, v: Vec3<T>) {
        self.x[m] = v.x;
        self.y[m] = v.y;
        self.z[m] = v.z;
    }
}

/// What one lane group reads. Each lane array starts a cache line (`LANES` reals are a
/// multiple of 64 bytes), so that no vector load of one splits across two: on the stack, their
/// alignment was whatever the callers' frames left, and one build's pair pass ran 10% slower
/// than another's with the same code (f64, one thread: the loads of these arrays the hottest
/// lines), its arrays 48 bytes past a line.
#[repr(C, align(64))]
struct Inputs<T> {
    /// The separation `r_i - r_j` (m, minimum image, residuals included).
    d: V3s<T>,
    r_i: [T; LANES],
    r_j: [T; LANES],
    m_i: [T; LANES],
    m_j: [T; LANES],
    v_i: V3s<T>,
    v_j: V3s<T>,
    w_i: V3s<T>,
    w_j: V3s<T>,
    v_eff: [T; LANES],
    g_eff: [T; LANES],
    mu_s: [T; LANES],
    beta: [T; LANES],
    xi: V3s<T>,
    /// Normal velocity at the previous evaluation (m/s).
    v_n: [T; LANES],
    /// Bridge volume (m^3), zero without cohesion.
    v_b: [T; LANES],
}

/// What one lane group writes, its arrays aligned as [`Inputs`]'.
#[repr(C, align(64))]
struct Outputs<T> {
    f_i: V3s<T>,
    f_j: V3s<T>,
    t_i: V3s<T>,
    t_j: V3s<T>,
    f_n: [T; LANES],
    f_c: [T; LANES],
    xi: V3s<T>,
    v_n: [T; LANES],
    clamped: [bool; LANES],
    /// The contact starts or ends inside the window ([`at_edge`]).
    edge: [bool; LANES],
    sliding: [bool; LANES],
}

/// Pairs sorted into touching and open at a time.
const WINDOW: usize = 256;
// The touching and open lists index a window with `u8`.
const _: () = assert!(WINDOW <= 256);

/// What the touch test of one window of pairs reads and finds, its arrays aligned as
/// [`Inputs`]'.
#[repr(C, align(64))]
struct Window<T> {
    /// `pos_i - pos_j`, then, once folded and completed, the separation (m).
    d: [[T; WINDOW]; 3],
    /// `residual_i - residual_j` (zero unless compensated).
    dr: [[T; WINDOW]; 3],
    r_i: [T; WINDOW],
    r_j: [T; WINDOW],
    touching: [bool; WINDOW],
    /// Each pair's owner grain.
    owner: [u32; WINDOW],
}

/// The lane kernel's working arrays, kept from call to call (each call overwrites what it
/// reads): a task of the pair pass would otherwise clear tens of kilobytes per few hundred
/// pairs.
pub struct Scratch<T> {
    win: Window<T>,
    /// The window's touching pairs, then its open ones, in pair order.
    touching: [u8; WINDOW],
    open: [u8; WINDOW],
}

impl<T: Real> Scratch<T> {
    /// Arrays of zeros.
    pub fn new() -> Box<Self> {
        let win = Window { d: [[T::ZERO; WINDOW]; 3], dr: [[T::ZERO; WINDOW]; 3], r_i: [T::ZERO; WINDOW], r_j: [T::ZERO; WINDOW], touching: [false; WINDOW], owner: [0; WINDOW] };
        Box::new(Scratch { win, touching: [0; WINDOW], open: [0; WINDOW] })
    }
}

impl<T: Real> Inputs<T> {
    /// Lanes of zeros, with unit masses so that the lanes of a first short group divide by
    /// no zero mass.
    fn new() -> Self {
        Inputs {
            d: V3s::ZERO,
            r_i: [T::ZERO; LANES],
            r_j: [T::ZERO; LANES],
            m_i: [T::ONE; LANES],
            m_j: [T::ONE; LANES],
            v_i: V3s::ZERO,
            v_j: V3s::ZERO,
            w_i: V3s::ZERO,
            w_j: V3s::ZERO,
            v_eff: [T::ZERO; LANES],
            g_eff: [T::ZERO; LANES],
            mu_s: [T::ZERO; LANES],
            beta: [T::ZERO; LANES],
            xi: V3s::ZERO,
            v_n: [T::ZERO; LANES],
            v_b: [T::ZERO; LANES],
        }
    }
}

impl<T: Real> Inputs<T> {
    /// Lane `l`'s contact: its geometry, kinematics, coefficients and history.
    #[inline(always)]
    fn lane(&self, l: usize) -> (Geometry<T>, Kinematics<T>, PairCoeffs<T>, History<T>) {
        let d = self.d.get(l);
        let geo = Geometry::grain_grain(d, d.norm2().sqrt(), self.r_i[l], self.r_j[l], self.m_i[l], self.m_j[l]);
        let kin = Kinematics { v_i: self.v_i.get(l), v_j: self.v_j.get(l), w_i: self.w_i.get(l), w_j: self.w_j.get(l) };
        let c = PairCoeffs { v_eff: self.v_eff[l], g_eff: self.g_eff[l], mu_s: self.mu_s[l], beta: self.beta[l], ..Default::default() };
        (geo, kin, c, History { tangential: self.xi.get(l), v_n: self.v_n[l], ..Default::default() })
    }
}

impl<T: Real> Outputs<T> {
    /// Lane `l`'s results: the contact force `f` and history `h` of the contact of geometry
    /// `geo`, with a touching bridge's pull f0 = -kappa sqrt(R_i R_j) added after the contact
    /// force as `contact_force` adds it, where bridges pull (`kappa`, N/m).
    #[inline(always)]
    fn set(&mut self, l: usize, f: &mut ContactForce<T>, h: &History<T>, geo: &Geometry<T>, kappa: Option<T>, inp: &Inputs<T>) {
        if let Some(kappa) = kappa {
            let f_c = if inp.v_b[l] > T::ZERO { -kappa * (inp.r_i[l] * inp.r_j[l]).sqrt() } else { T::ZERO };
            f.f_c = f_c;
            f.f_i += geo.n * f_c;
            f.f_j -= geo.n * f_c;
        }
        self.f_i.set(l, f.f_i);
        self.f_j.set(l, f.f_j);
        self.t_i.set(l, f.t_i);
        self.t_j.set(l, f.t_j);
        self.f_n[l] = f.f_n;
        self.f_c[l] = f.f_c;
        self.clamped[l] = f.clamped;
        self.sliding[l] = f.regime == Regime::Sliding;
        self.xi.set(l, h.tangential);
        self.v_n[l] = h.v_n;
    }
}

/// Where the lane kernel hands each pair's force.
pub trait PairSink<T> {
    /// Takes the force of the block's pair `m` (counted from its first pair), owned by grain
    /// `owner`. The touching pairs come in pair order; in capillary scenes each window's open
    /// pairs come before them.
    fn put(&mut self, m: usize, owner: usize, f: &ContactForce<T>);

    /// Pair `m` does not touch and has no bridge: its force is zero. Called in any order
    /// (in a dry scene, a window's open pairs before its touching ones). Returns false when
    /// the pair's records are known to be those of an open pair already, springs included,
    /// which the caller then need not clear.
    fn skip(&mut self, m: usize) -> bool;
}

impl<T: Copy + Default> PairSink<T> for [ContactForce<T>] {
    #[inline(always)]
    fn put(&mut self, m: usize, _owner: usize, f: &ContactForce<T>) {
        self[m] = *f;
    }

    #[inline(always)]
    fn skip(&mut self, m: usize) -> bool {
        self[m] = ContactForce::default();
        true
    }
}

/// The pair pass for pairs `first..first + n` under `model` (from [`hertz_mindlin`]), handed to
/// `sink`; `hist` holds their tangential springs (three reals per pair), their normal
/// velocities at the previous evaluation (a fourth) and, in capillary scenes, their bridge
/// volumes (a fifth).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn hertz_mindlin_block<T: Real, S: PairSink<T> + ?Sized>(model: &ContactModel<T>, scratch: &mut Scratch<T>, first: usize, n: usize, sink: &mut S, hist: &mut [T], pairs: &PairList, body: &[Body<T>], prop: &[Props<T>], ctx: &ForceContext<T>) {
    debug_assert!(ctx.slots.tangential == 0 && ctx.slots.normal == 3 && (!ctx.slots.layout.bridge || ctx.slots.bridge == 4), "the spring first, the normal velocity, the bridge after them");
    match ctx.model.cohesion {
        CohesionLaw::Capillary { kappa, .. } => lanes::<T, S, 5>(model, scratch, Some(kappa), first, n, sink, hist, pairs, body, prop, ctx),
        CohesionLaw::None => lanes::<T, S, 4>(model, scratch, None, first, n, sink, hist, pairs, body, prop, ctx),
    }
}

/// [`hertz_mindlin_block`] with `STRIDE` reals of history per pair (the bridge volume last
/// when 5) and `kappa` (N/m) when bridges pull. Each window of pairs is first tested for
/// touch, with no branch: the positions' scattered reads and the radii, then the fold and the
/// test in vector lanes over the window. The open pairs are done at once: dry and clamped, a
/// zero force and forgotten springs; wet, or where a parted contact may still pull
/// ([`ForceContext::ends_pull`]), `pair_force`'s short way (springs forgotten, a bridge's pull
/// across the gap, a contact's end). Only the touching ones, packed, load the rest of their grains and fill the
/// lanes (a third of a dense packing's listed pairs are open, most of a capillary scene's).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn lanes<T: Real, S: PairSink<T> + ?Sized, const STRIDE: usize>(model: &ContactModel<T>, scratch: &mut Scratch<T>, kappa: Option<T>, first: usize, n: usize, sink: &mut S, hist: &mut [T], pairs: &PairList, body: &[Body<T>], prop: &[Props<T>], ctx: &ForceContext<T>) {
    let Scratch { win, touching, open } = scratch;
    let mut inp = Inputs::new();
    // One material: every pair's coefficients are the same, set once in every lane.
    let uniform = ctx.n_materials == 1;
    if uniform {
        let c = &ctx.coeffs[0];
        (inp.v_eff, inp.g_eff, inp.mu_s, inp.beta) = ([c.v_eff; LANES], [c.g_eff; LANES], [c.mu_s; LANES], [c.beta; LANES]);
    }
    let mut res = Outputs { f_i: V3s::ZERO, f_j: V3s::ZERO, t_i: V3s::ZERO, t_j: V3s::ZERO, f_n: [T::ZERO; LANES], f_c: [T::ZERO; LANES], clamped: [false; LANES], edge: [false; LANES], sliding: [false; LANES], xi: V3s::ZERO, v_n: [T::ZERO; LANES] };
    for (w, hist) in hist[..STRIDE * n].chunks_mut(STRIDE * WINDOW).enumerate() {
        let (base, len) = (first + w * WINDOW, hist.len() / STRIDE);
        window_owners(pairs, base, &mut win.owner[..len]);
        // Touch test: the scattered reads one pair at a time, then the fold and the test in
        // vector lanes.
        for m in 0..len {
            // The partners a window ahead (in this task or the next), whose loads will then
            // find them in cache.
            if let Some(&j) = pairs.partner.get(base + m + WINDOW) {
                let b = &body[j as usize];
                super::simd::prefetch(&b.pos);
                super::simd::prefetch(&b.omega);
                super::simd::prefetch(&prop[j as usize]);
            }
            let (i, j) = (win.owner[m] as usize, pairs.partner[base + m] as usize);
            let (d, dr) = (body[i].pos - body[j].pos, residual_at(ctx.residual, i) - residual_at(ctx.residual, j));
            [win.d[0][m], win.d[1][m], win.d[2][m]] = [d.x, d.y, d.z];
            if T::COMPENSATED {
                // (f64's residuals are zero: nothing to store, nothing read.)
                [win.dr[0][m], win.dr[1][m], win.dr[2][m]] = [dr.x, dr.y, dr.z];
            }
            (win.r_i[m], win.r_j[m]) = (prop[i].radius, prop[j].radius);
        }
        for m in 0..len {
            let d = Vec3::new(win.d[0][m], win.d[1][m], win.d[2][m]);
            let d = complete(ctx.periodic.min_image(d), Vec3::new(win.dr[0][m], win.dr[1][m], win.dr[2][m]));
            [win.d[0][m], win.d[1][m], win.d[2][m]] = [d.x, d.y, d.z];
            let reach = win.r_i[m] + win.r_j[m];
            win.touching[m] = d.norm2() < reach * reach;
        }
        let (mut n_touching, mut n_open) = (0, 0);
        for m in 0..len {
            let t = win.touching[m];
            touching[n_touching] = m as u8;
            open[n_open] = m as u8;
            n_touching += t as usize;
            n_open += !t as usize;
        }
        let open_way = kappa.is_some() || ctx.ends_pull();
        for &m in &open[..n_open] {
            let m = m as usize;
            if open_way {
                let i = win.owner[m] as usize;
                sink.put(w * WINDOW + m, i, &super::pair_force::pair_force(i, base + m, pairs, body, prop, ctx, &mut hist[STRIDE * m..STRIDE * (m + 1)]));
            } else if sink.skip(w * WINDOW + m) {
                hist[STRIDE * m..STRIDE * m + 4].fill(T::ZERO);
            }
        }
        for group in touching[..n_touching].chunks(LANES) {
            // Load: the rest of the touching pairs' grains, one pair at a time.
            for (l, &m) in group.iter().enumerate() {
                let m = m as usize;
                let i = win.owner[m] as usize;
                let j = pairs.partner[base + m] as usize;
                let (bi, bj, pi, pj) = (&body[i], &body[j], &prop[i], &prop[j]);
                inp.d.set(l, Vec3::new(win.d[0][m], win.d[1][m], win.d[2][m]));
                (inp.r_i[l], inp.r_j[l], inp.m_i[l], inp.m_j[l]) = (win.r_i[m], win.r_j[m], pi.mass, pj.mass);
                inp.v_i.set(l, bi.vel);
                inp.v_j.set(l, bj.vel);
                inp.w_i.set(l, bi.omega);
                inp.w_j.set(l, bj.omega);
                if !uniform {
                    let c = ctx.pair_coeffs(i, j);
                    (inp.v_eff[l], inp.g_eff[l], inp.mu_s[l], inp.beta[l]) = (c.v_eff, c.g_eff, c.mu_s, c.beta);
                }
                let h = &hist[STRIDE * m..STRIDE * (m + 1)];
                inp.xi.set(l, Vec3::new(h[0], h[1], h[2]));
                inp.v_n[l] = h[3];
                inp.v_b[l] = if STRIDE == 5 { h[STRIDE - 1] } else { T::ZERO };
            }
            // Compute: every lane, with no branch the compiler cannot turn into a select
            // (lanes past the end of a short group recompute stale inputs, unstored), the
            // window's edges left out: each lane notes whether its contact starts or ends in
            // the window, and those few are done again one at a time with them.
            for l in 0..LANES {
                let (geo, kin, c, mut h) = inp.lane(l);
                let mut f = contact_force(model, &c, &geo, &kin, &Bodies::default(), &mut h, ctx.elapsed, KickWindow { span: ctx.window, edges: false });
                res.edge[l] = at_edge(model, geo.h, (kin.v_i - kin.v_j).dot(geo.n), h.v_n - inp.v_n[l], ctx.window);
                res.set(l, &mut f, &h, &geo, kappa, &inp);
            }
            for l in 0..group.len() {
                if res.edge[l] {
                    let (geo, kin, c, mut h) = inp.lane(l);
                    let mut f = contact_force(model, &c, &geo, &kin, &Bodies::default(), &mut h, ctx.elapsed, KickWindow::centred(ctx.window));
                    res.set(l, &mut f, &h, &geo, kappa, &inp);
                }
            }
            // Store.
            for (l, &m) in group.iter().enumerate() {
                let m = m as usize;
                sink.put(w * WINDOW + m, win.owner[m] as usize, &ContactForce { f_i: res.f_i.get(l), f_j: res.f_j.get(l), t_i: res.t_i.get(l), t_j: res.t_j.get(l), f_n: res.f_n[l], f_c: res.f_c[l], clamped: res.clamped[l], regime: if res.sliding[l] { Regime::Sliding } else { Regime::Static } });
                let xi = res.xi.get(l);
                hist[STRIDE * m..STRIDE * m + 4].copy_from_slice(&[xi.x, xi.y, xi.z, res.v_n[l]]);
            }
        }
    }
}

/// The owner of each pair `base..base + owner.len()`, without a branch per pair: a mark where
/// each owner's pairs begin (several where owners own none), summed along the window.
#[inline(always)]
fn window_owners(pairs: &PairList, base: usize, owner: &mut [u32]) {
    let first = pairs.owner_of(base);
    owner.fill(0);
    // `owner_start`'s last entry, the number of pairs, ends the walk.
    let mut q = first + 1;
    while (pairs.owner_start[q] as usize) < base + owner.len() {
        owner[pairs.owner_start[q] as usize - base] += 1;
        q += 1;
    }
    let mut sum = first as u32;
    for o in owner.iter_mut() {
        sum += *o;
        *o = sum;
    }
}

#[cfg(test)]
mod tests {
    //! The lane kernel against the one-pair pass, bit for bit, on a dense, shaken,
    //! periodic Hertz-Mindlin gas (touching and open pairs, sticking and slipping springs),
    //! dry and wet (bridges in contact and across gaps).
    use super::*;
    use crate::cpu::pair_force::pair_force;
    use crate::cpu::CpuEngine;
    use crate::engine::Engine;
    use crate::state::Load;
    use crate::cpu::wall_contacts::wall_contacts;

    /// A periodic gas under the lanes' law, shared with `tests/mpi.rs`.
    const SCENE: &str = include_str!("../../tests/fixtures/periodic_gas.toml");

    /// `SCENE` with a third of its grains of a second, stiffer and rougher material.
    fn two_materials() -> String {
        SCENE.replace("count = 1300", "count = 870").replace(
            "[periodic]",
            "[[material]]\nname = \"glass\"\ndensity = 2500.0\nyoungs_modulus = 2.0e8\npoisson_ratio = 0.25\nmu_s = 0.3\nrestitution = 0.7\n\n[[generate]]\nmaterial = \"glass\"\ncount = 430\ndiameter = { min = 0.9e-3, max = 1.1e-3 }\nregion = { shape = \"box\", min = [0.0, 0.0, 0.0], max = [14.0e-3, 14.0e-3, 14.0e-3] }\nrandom_speed = 0.5\n\n[periodic]",
        )
    }

    /// The lane kernel against the one-pair pass on `scene` (wetted with its water content
    /// first when `wet`), bit for bit.
    fn check<T: Real>(scene: &str, wet: bool) {
        let text = if wet { scene.replace("[[stage]]", "[[stage]]\nwater_content = 0.007").replace("[model]", "[model]\ncohesion = \"capillary\"") } else { scene.to_string() };
        let mut scene = crate::scene::parse(std::path::Path::new("lanes_test.toml"), &text).unwrap();
        // Grown 10% after placement: a dense, jostling gas.
        scene.grains.radius.iter_mut().for_each(|r| *r *= 1.1);
        let mut e = CpuEngine::<T>::new(&scene).unwrap();
        if let Some(v) = scene.stages[0].wet_volume {
            e.wet(v).unwrap();
        }
        e.advance(400).unwrap();
        let model = hertz_mindlin(&e.model).expect("the scene's model is Hertz-Mindlin");
        let ctx = ForceContext { model: &e.model, coeffs: &e.coeffs, n_materials: e.n_materials, slots: e.slots, elapsed: T::of(1.0e-7), window: T::of(1.0e-7), periodic: e.periodic, residual: &e.residual, material: &e.material, meshes: &e.meshes };
        let (n, stride) = (e.pairs.len(), e.slots.stride);
        let (mut hist_one, mut hist_lanes) = (e.hist.clone(), e.hist.clone());
        let one: Vec<ContactForce<T>> = e.pairs.owners_of(0..n).enumerate().map(|(k, i)| pair_force(i, k, &e.pairs, &e.body, &e.prop, &ctx, &mut hist_one[stride * k..stride * (k + 1)])).collect();
        let mut lanes = vec![ContactForce::default(); n];
        hertz_mindlin_block(&model, &mut Scratch::new(), 0, n, lanes.as_mut_slice(), &mut hist_lanes, &e.pairs, &e.body, &e.prop, &ctx);
        let touching = one.iter().filter(|f| f.f_n > T::ZERO).count();
        let springs = e.hist.chunks(stride).filter(|s| s[..3].iter().any(|x| *x != T::ZERO)).count();
        let open_bridges = one.iter().filter(|f| f.f_n == T::ZERO && f.f_c < T::ZERO).count();
        println!("{}: {n} pairs, {touching} pushing, {springs} springs, {open_bridges} bridges across a gap", T::NAME);
        assert!(touching > 100 && touching < n, "the gas must hold touching and open pairs");
        assert!(springs > 100, "the springs must have grown");
        assert!(!wet || open_bridges > 10, "the wet gas must hold bridges across gaps");
        let bits = |f: &ContactForce<T>| [f.f_i, f.f_j, f.t_i, f.t_j].iter().flat_map(|v| [v.x, v.y, v.z]).chain([f.f_n, f.f_c]).map(|x| x.f64().to_bits()).chain([f.clamped as u64, f.regime as u64]).collect::<Vec<_>>();
        let first = (0..n).find(|&k| bits(&one[k]) != bits(&lanes[k]));
        assert_eq!(first, None, "forces differ at pair {first:?}");
        let first = hist_one.iter().zip(&hist_lanes).position(|(a, b)| a.f64().to_bits() != b.f64().to_bits());
        assert_eq!(first, None, "springs differ at real {first:?}");
    }

    /// Each grain's load from the pair pass's owner sums and the gather against the sum the
    /// gather made when it read whole per-pair records (gravity, the owned pairs' forces on
    /// the owner in pair order, the forces on it as partner in pair order, the walls), bit for
    /// bit, on `SCENE` with its Mindlin law (the lanes) and with Oquendo et al.'s laws (one pair at a
    /// time, the force on the owner kept per pair; this gas has no pair in the rolling regime,
    /// where the two forces are not each other's reverse, so the count printed is 0).
    fn check_loads<T: Real>(oquendo: bool) {
        let text = if oquendo {
            SCENE.replace("restitution = 0.5", "restitution = 0.5\nmu_k = 0.4\nrolling_angle = 2.0\ngamma_n = 5.0e6\ngamma_nt = 100.0").replace(
                "damping = \"restitution\"\ntangential = \"mindlin\"\ntangential_damping_ratio = 0.9075",
                "damping = \"papers\"\ntangential = \"oquendo\"\ntwisting = \"oquendo\"\nstatic_damping = 0.3",
            )
        } else {
            SCENE.to_string()
        };
        // A floor in place of the period along z, so that walls add to the loads too.
        let text = text.replace("z = [0.0, 14.0e-3]\n", "").replace("[model]", "[[wall]]\ntype = \"plane\"\nmaterial = \"sand\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\n\n[model]");
        let mut scene = crate::scene::parse(std::path::Path::new("lanes_test.toml"), &text).unwrap();
        scene.grains.radius.iter_mut().for_each(|r| *r *= 1.1);
        scene.gravity = glam::DVec3::new(0.0, 0.0, -9.81);
        let mut e = CpuEngine::<T>::new(&scene).unwrap();
        e.advance(400).unwrap();
        let elapsed = T::of(1.0e-7);
        let ctx = ForceContext { model: &e.model, coeffs: &e.coeffs, n_materials: e.n_materials, slots: e.slots, elapsed, window: elapsed, periodic: e.periodic, residual: &e.residual, material: &e.material, meshes: &e.meshes };
        let (n, stride) = (e.pairs.len(), e.slots.stride);
        let mut hist = e.hist.clone();
        let one: Vec<ContactForce<T>> = e.pairs.owners_of(0..n).enumerate().map(|(k, i)| pair_force(i, k, &e.pairs, &e.body, &e.prop, &ctx, &mut hist[stride * k..stride * (k + 1)])).collect();
        let asymmetric = one.iter().filter(|f| f.f_i != -f.f_j).count();
        // The floor's loads, from the same history.
        let per_grain = crate::state::walls_reals(&e.walls, stride);
        let mut wall_hist = e.wall_springs.dense(e.body.len(), per_grain);
        let mut touches = Vec::new();
        let wall: Vec<Load<T>> = (0..e.body.len()).map(|i| wall_contacts(e.id[i], &e.body[i], crate::position::residual_at(&e.residual, i), &e.prop[i], ctx.material(i), &e.walls, &ctx, &mut wall_hist[i * per_grain..(i + 1) * per_grain], &mut touches, &mut None)).collect();
        assert!(!touches.is_empty(), "grains must touch the floor");
        e.evaluate_forces(elapsed, None, None);
        let p = &e.pairs;
        let first = (0..e.body.len()).find(|&i| {
            let (mut force, mut torque) = (e.gravity * e.prop[i].mass, Vec3::ZERO);
            for f in &one[p.owner_start[i] as usize..p.owner_start[i + 1] as usize] {
                force += f.f_i;
                torque += f.t_i;
            }
            for &k in &p.rev_pair[p.rev_start[i] as usize..p.rev_start[i + 1] as usize] {
                force += one[k as usize].f_j;
                torque += one[k as usize].t_j;
            }
            let (force, torque) = (force + wall[i].force, torque + wall[i].torque);
            let bits = |v: Vec3<T>| [v.x, v.y, v.z].map(|x| x.f64().to_bits());
            bits(force) != bits(e.load[i].force) || bits(torque) != bits(e.load[i].torque)
        });
        println!("{} {}: {n} pairs, {asymmetric} with f_i != -f_j, {} floor contacts", T::NAME, if oquendo { "oquendo" } else { "mindlin" }, touches.len());
        assert_eq!(first, None, "loads differ at grain {first:?}");
        let reports = (0..n).find(|&k| e.report.f_n[k] != one[k].f_n || e.report.regime(k) != one[k].regime || e.report.clamped(k) != one[k].clamped || e.owner_force(k) != one[k].f_i || e.share[k].torque != one[k].t_j);
        assert_eq!(reports, None, "the pair's report differs at pair {reports:?}");
    }

    /// Each pair's owner, found from `owner_start` alone, against the owners written out pair
    /// by pair, on a list whose first, middle and last grains own no pair, for every window
    /// start and length.
    #[test]
    fn owners_come_from_owner_start_alone() {
        // Grains 0, 2, 3 and 5 own nothing; 1 owns pairs 0-1, 4 owns 2-4, 6 owns 5.
        let pairs = PairList { owner_start: vec![0, 0, 2, 2, 2, 5, 5, 6], partner: vec![7; 6], ..Default::default() };
        let written: Vec<usize> = vec![1, 1, 4, 4, 4, 6];
        assert_eq!((0..6).map(|k| pairs.owner_of(k)).collect::<Vec<_>>(), written);
        for base in 0..6 {
            for len in 1..=6 - base {
                assert_eq!(pairs.owners_of(base..base + len).collect::<Vec<_>>(), written[base..base + len], "owners_of({base}..{})", base + len);
                let mut owner = vec![0u32; len];
                window_owners(&pairs, base, &mut owner);
                assert_eq!(owner.iter().map(|&o| o as usize).collect::<Vec<_>>(), written[base..base + len], "window at {base}, {len} pairs");
            }
        }
    }

    #[test]
    fn owner_sums_give_the_gathers_bits() {
        check_loads::<f64>(false);
        check_loads::<f32>(false);
        check_loads::<f64>(true);
    }

    #[test]
    fn lanes_give_the_one_pair_pass_bits_in_f64() {
        check::<f64>(SCENE, false);
    }

    #[test]
    fn lanes_give_the_one_pair_pass_bits_in_f32() {
        check::<f32>(SCENE, false);
    }

    #[test]
    fn lanes_give_the_one_pair_pass_bits_with_two_materials() {
        check::<f64>(&two_materials(), false);
        check::<f32>(&two_materials(), true);
    }

    #[test]
    fn lanes_give_the_one_pair_pass_bits_with_liquid_bridges() {
        check::<f64>(SCENE, true);
        check::<f32>(SCENE, true);
    }
}
