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

use super::{solve, Contact, WallMotion};
use crate::engine::Residuals;
use crate::real::Real;
use crate::state::Body;

/// The residuals of `contacts`' impulses against the bodies' velocities (which hold them).
pub(super) fn residuals<T: Real>(contacts: &[Contact<T>], body: &[Body<T>], walls: &[WallMotion<T>]) -> Residuals {
    let (mut out, mut miss2, mut wr2, mut wr, mut loaded, mut worst2) = (Residuals::default(), 0.0, 0.0, 0.0, 0usize, 0.0f64);
    for c in contacts {
        let d = solve::local(c, &body[c.a as usize], &solve::second_body(c, body, walls)) - c.r;
        let d_n = d.dot(c.n);
        out.normal = out.normal.max((c.w_n * d_n).f64().abs());
        out.tangential = out.tangential.max((c.w_t * (d - c.n * d_n).norm()).f64());
        let (miss, w_r) = (solve::weighted2(c, d).f64(), solve::weighted2(c, c.r).f64());
        worst2 = worst2.max(miss);
        miss2 += miss;
        wr2 += w_r;
        if c.r.dot(c.n) > T::ZERO {
            wr += w_r.sqrt();
            loaded += 1;
        }
    }
    if wr2 > 0.0 {
        out.quadratic = (miss2 / wr2).sqrt();
        out.maximum = worst2.sqrt() * loaded as f64 / wr;
    }
    out
}
