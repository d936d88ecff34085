//! One sweep of nonsmooth Gauss-Seidel: each contact's local problem solved exactly (see the
//! module text of [`super`]), colour by colour, then the serial tail; on the calling thread
//! here, shared by the pool's threads in [`super::parallel`].

use super::colour::Schedule;
use super::{parallel, Contact, Partner, Solved, SweepSettings, Sweeps, WallMotion};
use crate::engine::SimError;
use crate::state::Body;
use crate::real::{Real, Vec3};

/// Velocity of `b` against `a` at contact `c` (m/s): `v_b + w_b x (-R_b n) - v_a - w_a x (R_a n)`.
pub(super) fn relative_velocity<T: Real>(c: &Contact<T>, a: &Body<T>, b: &Body<T>) -> Vec3<T> {
    (b.vel + b.omega.cross(c.n * -c.radius_b)) - (a.vel + a.omega.cross(c.n * c.radius_a))
}

/// The second body of contact `c` as the local problem sees it: a grain, or a wall's motion
/// (a wall has no spin).
pub(super) fn second_body<T: Real>(c: &Contact<T>, body: &[Body<T>], walls: &[WallMotion<T>]) -> Body<T> {
    match c.b {
        Partner::Grain(j) => body[j as usize],
        Partner::Wall(w) => Body { pos: Vec3::ZERO, vel: walls[w as usize].vel, omega: Vec3::ZERO },
    }
}

/// Applies `-dr` to `a`, the first body of contact `c`.
pub(super) fn apply_a<T: Real>(c: &Contact<T>, a: &mut Body<T>, dr: Vec3<T>) {
    a.vel -= dr * c.inv_mass_a;
    a.omega -= (c.n * c.radius_a).cross(dr) * c.inv_inertia_a;
}

/// Applies `dr` to `b`, the second body of contact `c`. A wall (`b` standing for its motion)
/// moves along the contact normal only, guided in the other directions.
pub(super) fn apply_b<T: Real>(c: &Contact<T>, b: &mut Body<T>, dr: Vec3<T>) {
    match c.b {
        Partner::Grain(_) => {
            b.vel += dr * c.inv_mass_b;
            b.omega += (c.n * -c.radius_b).cross(dr) * c.inv_inertia_b;
        }
        Partner::Wall(_) => b.vel += c.n * (c.n.dot(dr) * c.inv_mass_b),
    }
}

/// Normal velocity of `b` against `a` at contact `c` (m/s): `(v_b - v_a) . n`, spin moving no
/// contact point along the normal.
fn normal_velocity<T: Real>(c: &Contact<T>, a: &Body<T>, b: &Body<T>) -> T {
    (b.vel - a.vel).dot(c.n)
}

/// Whether contact `c` carries no impulse and its bodies' normal velocity is at least its
/// `u_min`: its local solution is then no impulse ([`local`] reads the same normal velocity),
/// and solving it changes nothing. About half the contacts of a dense packing within the gap
/// allowance are open ones that stay open, and this is all a sweep computes for them.
pub(super) fn stays_open<T: Real>(c: &Contact<T>, a: &Body<T>, b: &Body<T>) -> bool {
    c.r == Vec3::ZERO && normal_velocity(c, a, b) >= c.u_min
}

/// Contact `c`'s impulse (N s, on `b`) solving its local problem exactly against the other
/// contacts' impulses, which the bodies' velocities hold with its own.
#[inline]
pub(super) fn local<T: Real>(c: &Contact<T>, a: &Body<T>, b: &Body<T>) -> Vec3<T> {
    let r_old = c.r;
    let own_n = r_old.dot(c.n);
    // The contact's velocity without its own impulse, its normal part from the grains' centres
    // alone (spin moves no contact point along `n`), as `stays_open` reads it.
    let u_n = normal_velocity(c, a, b) - c.w_n * own_n;
    let own_t = r_old - c.n * own_n;
    let u_other = relative_velocity(c, a, b) - c.n * (c.w_n * own_n) - own_t * c.w_t;
    let r_n = ((c.u_min - u_n) * c.inv_w_n).max(T::ZERO);
    let u_t = u_other - c.n * u_n;
    let stick = u_t * -c.inv_w_t;
    let cap = c.mu * r_n;
    let r_t = if stick.norm2() <= cap * cap {
        stick
    } else {
        let s = u_t.norm();
        if s > T::ZERO {
            u_t * (-cap / s)
        } else {
            Vec3::ZERO
        }
    };
    c.n * r_n + r_t
}

/// The impulse a sweep leaves at contact `c` from its local solution `star`: `star` itself
/// when `omega` is 1, else over-relaxed from the impulse before, `r + omega (star - r)`, and
/// put back in the admissible set (`r_n >= 0`, the tangential part clipped to the cone
/// `mu r_n` along itself).
fn relax<T: Real>(c: &Contact<T>, star: Vec3<T>, omega: T) -> Vec3<T> {
    if omega == T::ONE {
        return star;
    }
    let x = c.r + (star - c.r) * omega;
    let x_n = x.dot(c.n);
    let r_n = x_n.max(T::ZERO);
    let r_t = x - c.n * x_n;
    let cap = c.mu * r_n;
    let norm2 = r_t.norm2();
    let r_t = if norm2 <= cap * cap { r_t } else { r_t * (cap / norm2.sqrt()) };
    c.n * r_n + r_t
}

/// Solves contact `c` between bodies `a` and `b` one after the other: its new impulse
/// (relaxed by `omega`), applied; returns its share of the convergence measure.
pub(super) fn solve_serial<T: Real>(c: &mut Contact<T>, a: &mut Body<T>, b: &mut Body<T>, omega: T) -> (T, T) {
    if stays_open(c, a, b) {
        return (T::ZERO, T::ZERO);
    }
    let star = local(c, a, b);
    let r = relax(c, star, omega);
    let dr = r - c.r;
    // A change of exactly zero is not applied (it could only turn a velocity of -0 into +0),
    // as the WGSL twin does not apply it, so that both give the same bits.
    if dr != Vec3::ZERO {
        apply_a(c, a, dr);
        apply_b(c, b, dr);
    }
    let sum = measure(c, star - c.r, r);
    c.r = r;
    sum
}

/// `|W v|^2` ((m/s)^2): the squared velocity an impulse `v` (N s) gives contact `c` through its
/// local Delassus diagonal, `(w_n v_n)^2 + w_t^2 |v_t|^2`.
pub(super) fn weighted2<T: Real>(c: &Contact<T>, v: Vec3<T>) -> T {
    let v_n = v.dot(c.n);
    let normal = c.w_n * v_n;
    let tangential = (v - c.n * v_n) * c.w_t;
    normal * normal + tangential.norm2()
}

/// `(|W dr|^2, |W r|^2)`, a contact's share of the convergence measure: the squared velocity
/// correction its local solve made (`dr`, N s: how far it was from its law) and the squared
/// velocity its new impulse `r` gives it.
fn measure<T: Real>(c: &Contact<T>, dr: Vec3<T>, r: Vec3<T>) -> (T, T) {
    (weighted2(c, dr), weighted2(c, r))
}

/// Contacts per block of the convergence measure's sum: each block is summed in contact order,
/// then the blocks' sums in order (the GPU's `cd_measure` and `cd_decide` add the same way).
pub const MEASURE_BLOCK: usize = 256;

/// The square of a sweep's quadratic norm, `sum |W dr|^2 / sum |W r|^2` over its per-contact
/// measures, summed block by block ([`MEASURE_BLOCK`]) in contact order; 0 when no contact
/// carries an impulse.
pub(super) fn quadratic_norm2<T: Real>(sums: &[(T, T)]) -> T {
    let add = |(c, t): (T, T), &(dc, dt): &(T, T)| (c + dc, t + dt);
    let blocks: Vec<(T, T)> = sums.chunks(MEASURE_BLOCK).map(|b| b.iter().fold((T::ZERO, T::ZERO), add)).collect();
    let (change, total) = blocks.iter().fold((T::ZERO, T::ZERO), add);
    if total > T::ZERO {
        change / total
    } else {
        T::ZERO
    }
}

/// One sweep over every contact in the schedule's order on the calling thread; returns the
/// square of its quadratic norm ([`quadratic_norm2`]). `sums` holds each contact's share of
/// it; every entry is written, so it is only sized.
pub(super) fn sweep<T: Real>(contacts: &mut [Contact<T>], schedule: &Schedule, body: &mut [Body<T>], walls: &mut [WallMotion<T>], omega: T, sums: &mut Vec<(T, T)>) -> T {
    sums.resize(contacts.len(), (T::ZERO, T::ZERO));
    for range in schedule.colours() {
        for (c, sum) in contacts[range.clone()].iter_mut().zip(&mut sums[range]) {
            let Partner::Grain(j) = c.b else { unreachable!("colours hold grain pairs") };
            let (a, b) = two(body, c.a as usize, j as usize);
            *sum = solve_serial(c, a, b, omega);
        }
    }
    let tail = schedule.tail();
    solve_tail(&mut contacts[tail..], body, walls, &mut sums[tail..], omega);
    quadratic_norm2(sums)
}

/// Solves the serial tail's contacts (the wall contacts and any uncoloured pair) one after the
/// other, each share of the measure into `sums`.
pub(super) fn solve_tail<T: Real>(tail: &mut [Contact<T>], body: &mut [Body<T>], walls: &mut [WallMotion<T>], sums: &mut [(T, T)], omega: T) {
    for (c, sum) in tail.iter_mut().zip(sums) {
        *sum = match c.b {
            Partner::Grain(j) => {
                let (a, b) = two(body, c.a as usize, j as usize);
                solve_serial(c, a, b, omega)
            }
            Partner::Wall(w) => {
                let wall = &mut walls[w as usize];
                let mut b = Body { pos: Vec3::ZERO, vel: wall.vel, omega: Vec3::ZERO };
                let sum = solve_serial(c, &mut body[c.a as usize], &mut b, omega);
                wall.vel = b.vel;
                sum
            }
        };
    }
}

/// The sweeps on the CPU's threads: on the calling thread, or shared by the pool's threads
/// ([`super::parallel`]) when the settings allow it, there are several and the solve has at
/// least [`parallel::THREADS_MIN_CONTACTS`] contacts; the same bits either way.
#[derive(Default)]
pub struct CpuSweeps<T> {
    /// `(|W dr|^2, |W r|^2)` of each contact's last solve ((m/s)^2).
    sums: Vec<(T, T)>,
}

impl<T: Real> Sweeps<T> for CpuSweeps<T> {
    fn backend(&self) -> &'static str {
        "cpu"
    }

    fn solve(&mut self, contacts: &mut [Contact<T>], schedule: &Schedule, body: &mut [Body<T>], walls: &mut [WallMotion<T>], settings: SweepSettings<T>) -> Result<Solved, SimError> {
        if settings.shared && rayon::current_num_threads() > 1 && contacts.len() >= parallel::THREADS_MIN_CONTACTS && settings.max_iterations > 0 {
            return Ok(parallel::solve(contacts, schedule, body, walls, settings, &mut self.sums));
        }
        let mut solved = Solved::default();
        while solved.iterations < settings.max_iterations {
            let norm2 = sweep(contacts, schedule, body, walls, settings.relaxation, &mut self.sums);
            if solved.after_sweep(norm2, &settings) {
                break;
            }
        }
        Ok(solved)
    }
}

impl Solved {
    /// Counts a sweep whose quadratic norm squared was `norm2`; returns whether the sweeps stop:
    /// the norm fell to the settings' tolerance, or the cap of sweeps has run.
    pub(super) fn after_sweep<T: Real>(&mut self, norm2: T, settings: &SweepSettings<T>) -> bool {
        self.iterations += 1;
        self.sweep_norm = norm2.f64().sqrt();
        self.converged = norm2 <= settings.tolerance * settings.tolerance;
        self.converged || self.iterations >= settings.max_iterations
    }
}

/// Two different grains, mutably.
pub(super) fn two<T>(body: &mut [Body<T>], a: usize, b: usize) -> (&mut Body<T>, &mut Body<T>) {
    assert_ne!(a, b, "a contact joins two grains");
    if a < b {
        let (lo, hi) = body.split_at_mut(b);
        (&mut lo[a], &mut hi[0])
    } else {
        let (lo, hi) = body.split_at_mut(a);
        (&mut hi[0], &mut lo[b])
    }
}
