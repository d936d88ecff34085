//! How far a step's impulses are from the contact laws, measured after the solve on the final
//! velocities: each contact's local problem is solved once more against the others' impulses
//! (as a sweep would, without applying it), and the correction it would still make is the
//! contact's residual, in velocity (`W (r* - r)`, m/s, with `W` the local Delassus diagonal).
//! Its normal part is the Signorini-Newton violation (at a loaded contact `|u_n - u_min|`, the
//! speed at which it still interpenetrates or pulls; at an unloaded one `u_min - u_n` when it
//! closes faster than allowed), its tangential part the Coulomb violation (the slip left at a
//! contact inside the cone, or the slip's misalignment with a sliding impulse). Zero at every
//! contact is the exact solution of the step's problem.
//!
//! The norms follow LMGC90's practice for nonsmooth Gauss-Seidel: the quadratic norm
//! `sqrt(sum |W (r* - r)|^2 / sum |W r|^2)` and the maximum norm `max |W (r* - r)|` over the
//! mean `|W r|` of the loaded contacts, both without units.

use super::{solve, Contact, Partner, WallMotion};
use crate::engine::Residuals;
use crate::real::{Real, Vec3};
use crate::state::Body;

/// The residuals of `contacts`' impulses against the bodies' velocities (which hold them).
pub(super) fn residuals<T: Real>(contacts: &[Contact<T>], body: &[Body<T>], walls: &[WallMotion<T>]) -> Residuals {
    let (mut out, mut miss2, mut wr2, mut wr, mut loaded, mut worst) = (Residuals::default(), 0.0, 0.0, 0.0, 0usize, 0.0f64);
    for c in contacts {
        let b = match c.b {
            Partner::Grain(j) => body[j as usize],
            Partner::Wall(w) => Body { pos: Vec3::ZERO, vel: walls[w as usize].vel, omega: Vec3::ZERO },
        };
        let d = solve::local(c, &body[c.a as usize], &b) - c.r;
        let d_n = d.dot(c.n);
        let (normal, tangential) = ((c.w_n * d_n).f64().abs(), (c.w_t * (d - c.n * d_n).norm()).f64());
        let r_n = c.r.dot(c.n);
        let w_r = solve::weighted2(c, c.r).f64().sqrt();
        out.normal = out.normal.max(normal);
        out.tangential = out.tangential.max(tangential);
        let miss = normal.hypot(tangential);
        worst = worst.max(miss);
        miss2 += miss * miss;
        wr2 += w_r * w_r;
        if r_n > T::ZERO {
            wr += w_r;
            loaded += 1;
        }
    }
    if wr2 > 0.0 {
        out.quadratic = (miss2 / wr2).sqrt();
        out.maximum = worst * loaded as f64 / wr;
    }
    out
}
