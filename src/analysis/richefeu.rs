//! Richefeu et al.'s published figures (Richefeu, El Youssofi, Azema, Radjai 2009), for the reports
//! that set ours beside them.

/// `beta` of the dry force PDF's tail, `P ~ exp(-beta f/<f>)` (eq. 9, samples S_1 and S_4).
pub const BETA: f64 = 1.4;
/// `alpha_w` of both sides of the unconfined wet force PDF, `P ~ exp(-alpha_w |f|/f0)`
/// (eq. 10, sample S_6).
pub const ALPHA_W: f64 = 4.0;
/// Bonds per grain of the unconfined wet sample S_6: all, compressive, tensile.
pub const WET_BONDS: (f64, f64, f64) = (6.1, 2.97, 3.13);
/// Fraction of the dry packing's compressive forces below their mean: "more than" this.
pub const BELOW_MEAN: f64 = 0.6;
/// Confining pressure of S_7 over `p0` (sec. 4).
pub const CONFINED_OVER_P0: f64 = 0.5;
