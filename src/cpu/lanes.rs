//! The pair pass of the standard Hertz-Mindlin model (Hertz, restitution damping, Mindlin
//! tangential spring with one mu; no rolling or twisting: LAMMPS' and LIGGGHTS' default
//! granular model), with or without capillary bridges, in lanes that the compiler turns into
//! vector instructions.
//!
//! Each lane group is loaded one pair at a time (the scattered reads of the two grains),
//! then every lane runs the very same `contact_force` as the one-pair pass, with the laws
//! fixed at compile time and no branch on whether the pair touches (a third of a dense
//! packing's listed pairs do not, in no order a branch predictor learns): the result of a
//! pair that does not touch is dropped by a select. In capillary scenes, where most listed
//! pairs are open, each window of pairs is first sorted without a branch: the open ones take
//! `pair_force` itself (springs forgotten, a bridge's pull across the gap), the touching ones
//! fill the lanes, and a bridge adds its contact force `f0` by a select. Same operations on
//! the same inputs, so the same bits as `pair_force`; `tests` below check it.

use super::pair_force::ForceContext;
use super::pairs::PairList;
use super::state::{Body, Props};
use crate::model::{contact_force, Bodies, CohesionLaw, ContactForce, ContactModel, DampingLaw, Geometry, History, Kinematics, NormalLaw, PairCoeffs, Regime, RollingLaw, TangentialLaw, TangentialStiffness, TwistingLaw};
use crate::position::{complete, residual_at};
use crate::real::{Real, Vec3};

/// Pairs per lane group.
const LANES: usize = 32;

/// `model` rebuilt with its laws as compile-time constants when it is the standard
/// Hertz-Mindlin model (with any cohesion), so that the composed `contact_force` folds to
/// straight-line code; the lanes add the cohesion themselves.
#[inline(always)]
pub fn hertz_mindlin<T: Real>(model: &ContactModel<T>) -> Option<ContactModel<T>> {
    let TangentialLaw::Mindlin { damping_ratio, .. } = model.tangential else { return None };
    let fixed = ContactModel {
        normal: NormalLaw::Hertz,
        damping: DampingLaw::Restitution,
        tangential: TangentialLaw::Mindlin { damping_ratio, stiffness: TangentialStiffness::Mindlin },
        rolling: RollingLaw::None,
        twisting: TwistingLaw::None,
        cohesion: model.cohesion,
    };
    (*model == fixed).then_some(ContactModel { cohesion: CohesionLaw::None, ..fixed })
}

/// Three lanes of reals, one per component.
#[derive(Clone, Copy)]
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

/// What one lane group reads.
struct Inputs<T> {
    /// `pos_i - pos_j`, before the periodic fold.
    d: V3s<T>,
    /// `residual_i - residual_j` (zero unless compensated).
    dr: V3s<T>,
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
    /// Bridge volume (m^3), zero without cohesion.
    v_b: [T; LANES],
}

/// What one lane group writes.
struct Outputs<T> {
    f_i: V3s<T>,
    f_j: V3s<T>,
    t_i: V3s<T>,
    t_j: V3s<T>,
    f_n: [T; LANES],
    f_c: [T; LANES],
    clamped: [bool; LANES],
    sliding: [bool; LANES],
    xi: V3s<T>,
}

/// Pairs sorted into touching and open at a time.
const WINDOW: usize = 256;

/// Where the lane kernel hands each pair's force.
pub trait PairSink<T> {
    /// Takes the force of the block's pair `m` (counted from its first pair). Without cohesion
    /// the pairs come in pair order; in capillary scenes each window's open pairs come first.
    fn put(&mut self, m: usize, f: &ContactForce<T>);
}

impl<T: Copy> PairSink<T> for [ContactForce<T>] {
    #[inline(always)]
    fn put(&mut self, m: usize, f: &ContactForce<T>) {
        self[m] = *f;
    }
}

/// The pair pass for pairs `first..first + n` under `model` (from [`hertz_mindlin`]), handed to
/// `sink`; `hist` holds their tangential springs (three reals per pair) and, in capillary
/// scenes, their bridge volumes (a fourth).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn hertz_mindlin_block<T: Real, S: PairSink<T> + ?Sized>(model: &ContactModel<T>, first: usize, n: usize, sink: &mut S, hist: &mut [T], pairs: &PairList, body: &[Body<T>], prop: &[Props<T>], ctx: &ForceContext<T>) {
    debug_assert!(ctx.slots.tangential == 0 && (!ctx.slots.layout.bridge || ctx.slots.bridge == 3), "the spring first, the bridge after it");
    match ctx.model.cohesion {
        CohesionLaw::Capillary { kappa, .. } => lanes::<T, S, 4, true>(model, Some(kappa), first, n, sink, hist, pairs, body, prop, ctx),
        CohesionLaw::None => lanes::<T, S, 3, false>(model, None, first, n, sink, hist, pairs, body, prop, ctx),
    }
}

/// [`hertz_mindlin_block`] with `STRIDE` reals of history per pair (the bridge volume last
/// when 4) and `kappa` (N/m) when bridges pull. With `SORT`, each window of pairs is sorted
/// first, with no branch, into touching and open ones: the open ones take `pair_force`'s short
/// way (springs forgotten, a bridge's pull across the gap) and the touching ones fill the
/// lanes, packed; most of a capillary scene's listed pairs are open (the list reaches the
/// largest bridge's rupture distance), while in a dry packing a third are, and there the
/// lanes cost less than the sorting (the 8000-grain triaxial stage on one thread: 50 s
/// unsorted, 57 s sorted; the wet stage of wet_iso_0pa: 392 s sorted, 442 s unsorted).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn lanes<T: Real, S: PairSink<T> + ?Sized, const STRIDE: usize, const SORT: bool>(model: &ContactModel<T>, kappa: Option<T>, first: usize, n: usize, sink: &mut S, hist: &mut [T], pairs: &PairList, body: &[Body<T>], prop: &[Props<T>], ctx: &ForceContext<T>) {
    let mut inp = Inputs {
        d: V3s::ZERO,
        dr: V3s::ZERO,
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
        v_b: [T::ZERO; LANES],
    };
    let mut res = Outputs { f_i: V3s::ZERO, f_j: V3s::ZERO, t_i: V3s::ZERO, t_j: V3s::ZERO, f_n: [T::ZERO; LANES], f_c: [T::ZERO; LANES], clamped: [false; LANES], sliding: [false; LANES], xi: V3s::ZERO };
    let mut listed = [0u16; WINDOW];
    let mut open = [true; WINDOW];
    for (w, hist) in hist[..STRIDE * n].chunks_mut(STRIDE * WINDOW).enumerate() {
        let (base, len) = (first + w * WINDOW, hist.len() / STRIDE);
        let mut n_listed = 0;
        for (m, is_open) in open[..len].iter_mut().enumerate() {
            let keep = if SORT {
                let (i, j) = (pairs.owner[base + m] as usize, pairs.partner[base + m] as usize);
                let d = ctx.separation(body, i, j);
                let reach = prop[i].radius + prop[j].radius;
                d.norm2() < reach * reach
            } else {
                true
            };
            listed[n_listed] = m as u16;
            n_listed += keep as usize;
            *is_open = !keep;
        }
        if SORT {
            for m in (0..len).filter(|&m| open[m]) {
                sink.put(w * WINDOW + m, &super::pair_force::pair_force(base + m, pairs, body, prop, ctx, &mut hist[STRIDE * m..STRIDE * (m + 1)]));
            }
        }
        for group in listed[..n_listed].chunks(LANES) {
            // Load: the scattered reads, one pair at a time; first the positions alone, in a
            // short loop that keeps many of the partners' cache misses in flight.
            for (l, &m) in group.iter().enumerate() {
                let m = m as usize;
                let (i, j) = (pairs.owner[base + m] as usize, pairs.partner[base + m] as usize);
                inp.d.set(l, body[i].pos - body[j].pos);
                inp.dr.set(l, residual_at(ctx.residual, i) - residual_at(ctx.residual, j));
            }
            for (l, &m) in group.iter().enumerate() {
                let m = m as usize;
                let i = pairs.owner[base + m] as usize;
                let j = pairs.partner[base + m] as usize;
                let (bi, bj, pi, pj) = (&body[i], &body[j], &prop[i], &prop[j]);
                (inp.r_i[l], inp.r_j[l], inp.m_i[l], inp.m_j[l]) = (pi.radius, pj.radius, pi.mass, pj.mass);
                inp.v_i.set(l, bi.vel);
                inp.v_j.set(l, bj.vel);
                inp.w_i.set(l, bi.omega);
                inp.w_j.set(l, bj.omega);
                let c = &ctx.coeffs[pi.material as usize * ctx.n_materials + pj.material as usize];
                (inp.v_eff[l], inp.g_eff[l], inp.mu_s[l], inp.beta[l]) = (c.v_eff, c.g_eff, c.mu_s, c.beta);
                let h = &hist[STRIDE * m..STRIDE * (m + 1)];
                inp.xi.set(l, Vec3::new(h[0], h[1], h[2]));
                inp.v_b[l] = if STRIDE == 4 { h[STRIDE - 1] } else { T::ZERO };
            }
            // Compute: every lane, touching or not, with no branch the compiler cannot turn
            // into a select (unsorted, the result of a pair that does not touch is dropped;
            // lanes past the end of a short group recompute stale inputs, unstored).
            for l in 0..LANES {
                let d = complete(ctx.periodic.min_image(inp.d.get(l)), inp.dr.get(l));
                let dist2 = d.norm2();
                let reach = inp.r_i[l] + inp.r_j[l];
                let touching = dist2 < reach * reach;
                let geo = Geometry::grain_grain(d, dist2.sqrt(), inp.r_i[l], inp.r_j[l], inp.m_i[l], inp.m_j[l]);
                let kin = Kinematics { v_i: inp.v_i.get(l), v_j: inp.v_j.get(l), w_i: inp.w_i.get(l), w_j: inp.w_j.get(l) };
                let c = PairCoeffs { v_eff: inp.v_eff[l], g_eff: inp.g_eff[l], mu_s: inp.mu_s[l], beta: inp.beta[l], ..Default::default() };
                let mut h = History { tangential: inp.xi.get(l), ..Default::default() };
                let f = contact_force(model, &c, &geo, &kin, &Bodies::default(), &mut h, ctx.elapsed);
                let mut f = if touching { f } else { ContactForce::default() };
                // A touching bridge pulls with f0 = -kappa sqrt(R_i R_j), added after the
                // contact force as `contact_force` adds it (only sorted lanes hold bridges).
                if let Some(kappa) = kappa {
                    let f_c = if inp.v_b[l] > T::ZERO { -kappa * (inp.r_i[l] * inp.r_j[l]).sqrt() } else { T::ZERO };
                    f.f_c = f_c;
                    f.f_i += geo.n * f_c;
                    f.f_j -= geo.n * f_c;
                }
                res.f_i.set(l, f.f_i);
                res.f_j.set(l, f.f_j);
                res.t_i.set(l, f.t_i);
                res.t_j.set(l, f.t_j);
                res.f_n[l] = f.f_n;
                res.f_c[l] = f.f_c;
                res.clamped[l] = f.clamped;
                res.sliding[l] = f.regime == Regime::Sliding;
                res.xi.set(l, if touching { h.tangential } else { Vec3::ZERO });
            }
            // Store.
            for (l, &m) in group.iter().enumerate() {
                let m = m as usize;
                sink.put(w * WINDOW + m, &ContactForce { f_i: res.f_i.get(l), f_j: res.f_j.get(l), t_i: res.t_i.get(l), t_j: res.t_j.get(l), f_n: res.f_n[l], f_c: res.f_c[l], clamped: res.clamped[l], regime: if res.sliding[l] { Regime::Sliding } else { Regime::Static } });
                let xi = res.xi.get(l);
                hist[STRIDE * m..STRIDE * m + 3].copy_from_slice(&[xi.x, xi.y, xi.z]);
            }
        }
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
    use crate::cpu::state::Load;
    use crate::cpu::wall_contacts::wall_contacts;

    const SCENE: &str = r#"
seed = 5
[[material]]
name = "sand"
density = 2650.0
youngs_modulus = 7.0e7
poisson_ratio = 0.3
mu_s = 0.5
restitution = 0.5

[[generate]]
material = "sand"
count = 1300
diameter = { min = 0.8e-3, max = 1.2e-3 }
region = { shape = "box", min = [0.0, 0.0, 0.0], max = [14.0e-3, 14.0e-3, 14.0e-3] }
random_speed = 0.5

[periodic]
x = [0.0, 14.0e-3]
y = [0.0, 14.0e-3]
z = [0.0, 14.0e-3]

[model]
normal = "hertz"
damping = "restitution"
tangential = "mindlin"
tangential_damping_ratio = 0.9075

[[stage]]
kind = "run"
duration = 1.0e-3
"#;

    /// The lane kernel against the one-pair pass on `SCENE` (wetted with its water content
    /// first when `wet`), bit for bit.
    fn check<T: Real>(wet: bool) {
        let text = if wet { SCENE.replace("[[stage]]", "[[stage]]\nwater_content = 0.007").replace("[model]", "[model]\ncohesion = \"capillary\"") } else { SCENE.to_string() };
        let mut scene = crate::scene::parse(std::path::Path::new("lanes_test.toml"), &text).unwrap();
        // Grown 10% after placement: a dense, jostling gas.
        scene.grains.radius.iter_mut().for_each(|r| *r *= 1.1);
        let mut e = CpuEngine::<T>::new(&scene).unwrap();
        if let Some(v) = scene.stages[0].wet_volume {
            e.wet(v).unwrap();
        }
        e.advance(400).unwrap();
        let model = hertz_mindlin(&e.model).expect("the scene's model is Hertz-Mindlin");
        let ctx = ForceContext { model: &e.model, coeffs: &e.coeffs, n_materials: e.n_materials, slots: e.slots, elapsed: T::of(1.0e-7), periodic: e.periodic, residual: &e.residual };
        let (n, stride) = (e.pairs.len(), e.slots.stride);
        let (mut hist_one, mut hist_lanes) = (e.hist.clone(), e.hist.clone());
        let one: Vec<ContactForce<T>> = (0..n).map(|k| pair_force(k, &e.pairs, &e.body, &e.prop, &ctx, &mut hist_one[stride * k..stride * (k + 1)])).collect();
        let mut lanes = vec![ContactForce::default(); n];
        hertz_mindlin_block(&model, 0, n, lanes.as_mut_slice(), &mut hist_lanes, &e.pairs, &e.body, &e.prop, &ctx);
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
    /// bit, on `SCENE` with its Mindlin law (the lanes) and with seed 000's laws (one pair at a
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
        scene.gravity = [0.0, 0.0, -9.81];
        let mut e = CpuEngine::<T>::new(&scene).unwrap();
        e.advance(400).unwrap();
        let elapsed = T::of(1.0e-7);
        let ctx = ForceContext { model: &e.model, coeffs: &e.coeffs, n_materials: e.n_materials, slots: e.slots, elapsed, periodic: e.periodic, residual: &e.residual };
        let (n, stride) = (e.pairs.len(), e.slots.stride);
        let mut hist = e.hist.clone();
        let one: Vec<ContactForce<T>> = (0..n).map(|k| pair_force(k, &e.pairs, &e.body, &e.prop, &ctx, &mut hist[stride * k..stride * (k + 1)])).collect();
        let asymmetric = one.iter().filter(|f| f.f_i != -f.f_j).count();
        // The floor's loads, from the same history.
        let per_grain = e.walls.len() * stride;
        let mut wall_hist = e.wall_hist.clone();
        let mut touches = Vec::new();
        let wall: Vec<Load<T>> = (0..e.body.len()).map(|i| wall_contacts(e.id[i], &e.body[i], crate::position::residual_at(&e.residual, i), &e.prop[i], &e.walls, &ctx, &mut wall_hist[i * per_grain..(i + 1) * per_grain], &mut touches)).collect();
        assert!(!touches.is_empty(), "grains must touch the floor");
        e.evaluate_forces(elapsed);
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

    #[test]
    fn owner_sums_give_the_gathers_bits() {
        check_loads::<f64>(false);
        check_loads::<f32>(false);
        check_loads::<f64>(true);
    }

    #[test]
    fn lanes_give_the_one_pair_pass_bits_in_f64() {
        check::<f64>(false);
    }

    #[test]
    fn lanes_give_the_one_pair_pass_bits_in_f32() {
        check::<f32>(false);
    }

    #[test]
    fn lanes_give_the_one_pair_pass_bits_with_liquid_bridges() {
        check::<f64>(true);
        check::<f32>(true);
    }
}
