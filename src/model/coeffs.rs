//! What a contact law reads besides the geometry: the materials' constants, each pair of
//! materials' mixed coefficients, and the layout of the history a contact keeps.

use super::*;

/// Which per-contact history blocks exist: world-frame 3-vectors (m) and single reals; a
/// block a model does not use is not allocated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct HistoryLayout {
    /// Accumulated tangential spring displacement `xi` (m).
    pub tangential: bool,
    /// The normal velocity at the previous evaluation (m/s), one real: damped laws, whose
    /// dashpot sees the velocity carried forward from it ([`window`]).
    pub normal: bool,
    /// Whether the contact is sliding (one real, 0 or 1): friction with two coefficients.
    pub sliding: bool,
    /// Accumulated rolling displacement `psi` (m): the rolling law's, or Oquendo et al.'s rolling
    /// spring.
    pub rolling: bool,
    /// Liquid bridge volume `V_b` (m^3), one real.
    pub bridge: bool,
}

impl HistoryLayout {
    /// Reals a contact's history holds: 3 per spring, 1 for the normal velocity, 1 for the
    /// sliding flag, 1 for a bridge.
    pub fn reals(&self) -> usize {
        3 * self.tangential as usize + self.normal as usize + self.sliding as usize + 3 * self.rolling as usize + self.bridge as usize
    }
}

/// Per-contact history, world frame, zero when a contact forms.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct History<T> {
    /// Tangential spring displacement `xi` (m).
    pub tangential: Vec3<T>,
    /// The normal velocity the contact forces drive at the previous evaluation (m/s,
    /// [`driven_normal_velocity`]); 0 in a new contact.
    pub v_n: T,
    /// Sliding at the last evaluation (Oquendo et al.'s regimes).
    pub sliding: bool,
    /// Rolling spring displacement `psi` (m).
    pub rolling: Vec3<T>,
    /// Liquid bridge volume (m^3); 0 without a bridge.
    pub bridge: T,
}

/// Coefficients of one pair of materials (see [`PairCoeffs::of`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PairCoeffs<T> {
    /// `V_eff = V_i V_j / (V_i + V_j)` (Pa), `V = E / (1 - nu^2)`.
    pub v_eff: T,
    /// Mindlin `G_eff`: `1/G_eff = (2 - nu_i)/G_i + (2 - nu_j)/G_j` (Pa).
    pub g_eff: T,
    /// Static friction coefficient (-).
    pub mu_s: T,
    /// Kinetic friction coefficient (-).
    pub mu_k: T,
    /// `tan(theta_r)` of the rolling angle (-).
    pub tan_roll: T,
    /// Papers' normal damping `gamma_n` (s^-1 m^-1/2).
    pub gamma_n: T,
    /// Twisting damping `gamma_nt` (s^-1).
    pub gamma_nt: T,
    /// Dashpot ratio `beta` (-) of `damping = "restitution"`, found for the mean restitution
    /// of the two materials ([`restitution::dashpot_ratio`]); 0 under other damping laws.
    pub beta: T,
}

/// The mechanical constants of one material, in SI units.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MaterialConstants {
    /// Young's modulus (Pa).
    pub youngs_modulus: f64,
    /// Poisson ratio (-).
    pub poisson_ratio: f64,
    /// Static friction coefficient (-).
    pub mu_s: f64,
    /// Kinetic friction coefficient (-).
    pub mu_k: f64,
    /// Rolling angle `theta_r` (rad).
    pub rolling_angle: f64,
    /// `gamma_n` (s^-1 m^-1/2).
    pub gamma_n: f64,
    /// `gamma_nt` (s^-1).
    pub gamma_nt: f64,
    /// Restitution coefficient (-), used by [`DampingLaw::Restitution`].
    pub restitution: f64,
}

impl MaterialConstants {
    /// `V = E / (1 - nu^2)` (Pa).
    pub fn stiffness(&self) -> f64 {
        self.youngs_modulus / (1.0 - self.poisson_ratio * self.poisson_ratio)
    }
    /// Shear modulus `G = E / (2 (1 + nu))` (Pa).
    pub fn shear_modulus(&self) -> f64 {
        self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))
    }
    /// `V_eff = V_a V_b / (V_a + V_b)` (Pa) of a contact between materials `a` and `b`.
    pub fn effective_stiffness(a: &Self, b: &Self) -> f64 {
        let (va, vb) = (a.stiffness(), b.stiffness());
        va * vb / (va + vb)
    }
}

/// The coefficients a contact between two materials takes from a mixing rule, or from the
/// scene's `[[pair]]` table where it gives them: friction, rolling, damping and restitution
/// (the elastic moduli are the materials' own and always combine by docs/physics.md). Each is a
/// value ([`MixedConstants`]) or one a table may leave out ([`MixedOverride`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Mixed<V> {
    /// Static friction coefficient (-).
    pub mu_s: V,
    /// Kinetic friction coefficient (-).
    pub mu_k: V,
    /// Rolling angle `theta_r` (rad).
    pub rolling_angle: V,
    /// `gamma_n` (s^-1 m^-1/2).
    pub gamma_n: V,
    /// `gamma_nt` (s^-1).
    pub gamma_nt: V,
    /// Restitution coefficient (-), of [`DampingLaw::Restitution`].
    pub restitution: V,
}

/// A pair of materials' mixed coefficients.
pub type MixedConstants = Mixed<f64>;

/// What a `[[pair]]` table gives for its pair of materials; what it leaves out (`None`) comes
/// from the mixing rule, except `mu_k`, which follows a given `mu_s` as a material's does.
pub type MixedOverride = Mixed<Option<f64>>;

impl MixedConstants {
    /// The mixing rule: friction coefficients and the rolling angle take the smaller of the
    /// two (as YADE does: a frictionless wall makes frictionless contacts); damping and
    /// restitution take the arithmetic mean. Equal materials give their own values.
    pub fn rule(a: &MaterialConstants, b: &MaterialConstants) -> Self {
        let mean = |x: f64, y: f64| 0.5 * (x + y);
        MixedConstants {
            mu_s: a.mu_s.min(b.mu_s),
            mu_k: a.mu_k.min(b.mu_k),
            rolling_angle: a.rolling_angle.min(b.rolling_angle),
            gamma_n: mean(a.gamma_n, b.gamma_n),
            gamma_nt: mean(a.gamma_nt, b.gamma_nt),
            restitution: mean(a.restitution, b.restitution),
        }
    }
}

impl MixedOverride {
    /// `rule` with what this table gives in place of the rule's values.
    pub fn over(&self, rule: MixedConstants) -> MixedConstants {
        MixedConstants {
            mu_s: self.mu_s.unwrap_or(rule.mu_s),
            mu_k: self.mu_k.or(self.mu_s).unwrap_or(rule.mu_k),
            rolling_angle: self.rolling_angle.unwrap_or(rule.rolling_angle),
            gamma_n: self.gamma_n.unwrap_or(rule.gamma_n),
            gamma_nt: self.gamma_nt.unwrap_or(rule.gamma_nt),
            restitution: self.restitution.unwrap_or(rule.restitution),
        }
    }
}

impl<T: Real> PairCoeffs<T> {
    /// Coefficients for a contact between materials `a` and `b` whose mixed constants are
    /// `mixed` ([`MixedConstants::rule`], or the scene's pair table): elastic constants
    /// combine as docs/physics.md rules. The dashpot ratio is sized for `model`'s normal law
    /// and clamp.
    pub fn of(a: &MaterialConstants, b: &MaterialConstants, mixed: &MixedConstants, model: &ContactModel<f64>) -> Self {
        let g_inv = (2.0 - a.poisson_ratio) / a.shear_modulus() + (2.0 - b.poisson_ratio) / b.shear_modulus();
        PairCoeffs {
            v_eff: T::of(MaterialConstants::effective_stiffness(a, b)),
            g_eff: T::of(1.0 / g_inv),
            mu_s: T::of(mixed.mu_s),
            mu_k: T::of(mixed.mu_k),
            tan_roll: T::of(mixed.rolling_angle.tan()),
            gamma_n: T::of(mixed.gamma_n),
            gamma_nt: T::of(mixed.gamma_nt),
            beta: T::of(match model.damping {
                DampingLaw::Restitution => restitution::dashpot_ratio(mixed.restitution, model.normal.spring(), model.limit_damping),
                _ => 0.0,
            }),
        }
    }
}
