//! Contact of a rigid cylindrical punch with the half-plane: the model, the state at one
//! instant, field evaluation, and the surface fields of seed eqs. (64)–(65).
//!
//! # Conventions (fretsim's, physical)
//! - x along the surface in the *material* frame; the punch axis is at x = 0 (its tangential
//!   rigid displacement is of the order of the elastic displacements and is neglected in the
//!   geometry, as in all small-strain contact theory). The contact is `[c − a, c + a]`; the
//!   seed paper's eccentricity (punch axis relative to the contact centre) is `e = −c`.
//! - `p` compressive positive; `q` the shear traction the punch exerts *on the half-plane*
//!   (+x positive), so `∫q = Q` is the tangential force applied to the punch; `g = −Dz(x,0⁺)`
//!   as in the seed paper; `uz` positive into the solid, so the rigid cylinder imposes
//!   `∂uz/∂x = −x/R` on the contact.
//! - The seed paper's `q` is the traction on the punch (`q_paper = −q`): its solution for a given
//!   Q is the mirror image x → −x of ours (see [`crate::halfplane`] for the coefficient map).
//!
//! # Equations on the contact (from (A)–(C) of [`crate::halfplane`])
//! Write the charge as `g = χ p + w`:
//! - conducting punch (φ constant on the contact): `χ = k = −y23/y33` and, from (C),
//!   `y33 H'w = −w13 q`, `∫w = Γ − kP` (seed eqs. 23, 26–29: `g1 = k p` is the part carried by
//!   the pressure, `w = g2` the part held by the constant potential);
//! - insulating punch: `g ≡ 0` (`χ = 0`, `w = 0`). The seed paper says the conducting punch,
//!   unlike the insulating one, puts charge on the contact surface, and its trends confirm this
//!   reading: with `g ≡ 0` we get the smaller stick zone and the larger |C| it reports for the
//!   insulating punch at every η, while the alternative `g = (Γ/P) p` gives the opposite order
//!   (PZT-4, R = 60 mm, P = 2000 N/m, η = 0.3: b/a = 0.954 conducting, 0.343 for `g ≡ 0`,
//!   0.991 for `g = (Γ/P)p`). Γ therefore has no effect under an insulating punch;
//! - elastic half-plane: `χ = 0`, `w = 0`.
//!
//! Eliminating g from (B) gives the pressure equation (seed eqs. 21/46):
//!
//! ```text
//! Y* H'p(x) = −x/R − κ q(x),   Y* = y22 + χ y23,   κ = w12 − y23 w13/y33 (conducting) or w12
//! ```
//!
//! and, from (A), the tangential equation `y11 H'q = ∂ux/∂x + (w12 + χ w13) p + w13 w`.
//! For the frictionless elastic case `Y* = 2/E*` and `p = p0 √(1 − x²/a²)`,
//! `a² = 2PRY*/π` (Hertz). `κ/Y*` is Dundurs' β for an elastic solid.
//!
//! # Zhou & Lee's frictionless conducting solution (derived from seed eqs. 24–29 with q = 0)
//! With q = 0 the pressure equation is Hertz's with compliance `Y*`: `c = 0`,
//! `a² = 2PRY*/π`, `p = (2P/(πa²))√(a² − x²)`. The charge equation `y33 H'w = 0` with
//! `∫w = Γ − kP` has the bounded-at-neither-end solution `w = (Γ − kP)/(π√(a² − x²))`, so
//! `g(x) = k p(x) + (Γ − kP)/(π√(a² − x²))`. With the regularised kernel
//! `∫₀^∞ cos(sr)/s ds → −ln(|r|/d)` (datum distance d) the contact potential is
//! `φ0 = (ln(2d/a)/π)(y23 P + y33 Γ) − (w13/π) ∫ q(s) arcsin((s − c)/a) ds`: the weighted mean of
//! φ over the contact with weight `1/√(a² − x²)`, exact because φ is constant there and
//! `(1/π)∫ ln|x − s| dx/√(a² − x²) = ln(a/2)` for every s in the contact.
//! Under potential control (φ0 given) this relation gives Γ.
//!
//! # Surface in-plane fields (seed eqs. 64–65, re-derived)
//! ```text
//! σxx0 = −Δ1 p − Δ2 g + Δ3 ∂ux/∂x,      ∂ux/∂x = −w12 p − w13 g + y11 H'q
//! Dx0  = −(e15/c44) q − Δ4 ∂φ/∂x,        ∂φ/∂x  =  w13 q + y23 H'p + y33 H'g
//! ```
//! valid on and off the contact (off it p = q = g = 0 and only the Cauchy terms remain).

pub mod frictionless;
mod gap_table;
internal! { mod general; }
pub mod memory;
pub mod normal;
internal! { mod pressure; }
internal! { mod profile; }
internal! { mod roots; }
internal! { mod tangential; }

mod inherited;
mod kinks;
pub(crate) mod rules;
mod state;
pub(crate) mod stick_zone;
mod surface;

use serde::Serialize;

use crate::error::MaterialFailure;
use crate::halfplane::{SurfaceCompliance, SurfaceFieldCoefficients};
use crate::material::Material;
pub use gap_table::{GapTable, TableIssue};
pub(crate) use inherited::smootherstep;
pub use pressure::Discretisation;
pub use profile::Profile;
pub use state::{ContactState, Traction};
pub use surface::SurfacePoint;
pub use tangential::{Accelerations, SlipOptions};

internal_use! { inherited::{Inherited, RememberedRoot}; }
internal_use! {
    kinks::{
        Kink, Kinks, half_ellipse, half_ellipse_cauchy, half_ellipse_integral, kink_cauchy,
        kink_density, kink_domain,
    };
}
internal_use! {
    rules::{
        GradedTable, field_rule_nodes, graded_cumulative, graded_nodes, graded_rule,
        slip_check_rule_nodes, slip_zone_rule_nodes, slip_zone_smooth_nodes, step_breakpoints,
    };
}
internal_use! { stick_zone::{StickZone, ZoneTables}; }
internal_use! { surface::GapReport; }

/// How the punch is connected electrically (piezoelectric half-plane only).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Electrode {
    /// Elastic half-plane: no electric field.
    None,
    /// Perfectly conducting punch carrying the resultant charge Γ (C/m); φ0 is computed.
    ConductingCharge {
        /// Γ (C/m).
        charge: f64,
    },
    /// Perfectly conducting punch held at potential φ0 (V) relative to the datum; Γ is computed.
    ConductingPotential {
        /// φ0 (V).
        potential: f64,
    },
    /// Insulating punch: no charge on the contact surface, `g ≡ 0` (module docs).
    Insulating,
}

/// Whether the shear traction is fed back into the pressure equation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Coupling {
    /// Full coupling (κ as derived).
    #[default]
    Full,
    /// Goodman's approximation: κ = 0 in the pressure equation (q does not change p).
    Goodman,
}

/// Everything that defines the contact except the loads and the history.
#[derive(Debug, Clone, Serialize)]
pub struct ContactModel {
    /// The half-plane.
    pub material: Material,
    /// Surface compliance coefficients derived from the material.
    pub compliance: SurfaceCompliance,
    /// Δ1…Δ4 for the surface fields.
    pub field_coefficients: SurfaceFieldCoefficients,
    /// The punch's profile.
    pub profile: Profile,
    /// Coulomb friction coefficient η (–).
    pub friction: f64,
    /// Electric boundary condition of the punch.
    pub electrode: Electrode,
    /// Datum distance d of the regularised log kernel (m), for φ0 and the displacement δ.
    pub reference_distance: f64,
    /// Shear–pressure coupling.
    pub coupling: Coupling,
    /// Whether p and w carry their square-root kinks at the stick ends in closed form
    /// ([`Kinks`]; default on). Off gives the plain series of the seed paper: slower
    /// convergence in M, but it completes two histories that the kinks stop (README).
    pub stick_end_kinks: bool,
}

/// How the charge is split, `g = χ p + w`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, serde::Deserialize)]
pub struct ChargeSplit {
    /// χ (C/N).
    pub ratio: f64,
    /// Whether the constant-potential part `w` is present (conducting punch).
    pub conducting: bool,
}

impl ContactModel {
    /// A model with the coefficients derived from `material`, or why the constants give no
    /// surface response ([`SurfaceCompliance::try_of`]).
    pub fn try_new(
        material: Material,
        profile: Profile,
        friction: f64,
        electrode: Electrode,
    ) -> Result<Self, MaterialFailure> {
        Ok(Self {
            compliance: SurfaceCompliance::try_of(&material)?,
            field_coefficients: SurfaceFieldCoefficients::of(&material),
            material,
            profile,
            friction,
            electrode,
            reference_distance: 1e-2,
            coupling: Coupling::Full,
            stick_end_kinks: true,
        })
    }

    /// A model with the coefficients derived from a material known to be sound (the presets,
    /// tests).
    ///
    /// # Panics
    /// If [`Self::try_new`] fails; use that on constants from the user.
    pub fn new(material: Material, profile: Profile, friction: f64, electrode: Electrode) -> Self {
        Self::try_new(material, profile, friction, electrode)
            .unwrap_or_else(|e| panic!("contact model: {e}"))
    }

    /// With the kinks at the stick ends on or off.
    pub fn with_stick_end_kinks(mut self, on: bool) -> Self {
        self.stick_end_kinks = on;
        self
    }

    /// With a datum distance d (m).
    pub fn with_reference_distance(mut self, d: f64) -> Self {
        self.reference_distance = d;
        self
    }

    /// With the given shear–pressure coupling.
    pub fn with_coupling(mut self, coupling: Coupling) -> Self {
        self.coupling = coupling;
        self
    }

    /// χ and the conducting flag at normal load P.
    pub fn charge_split(&self, _normal_load: f64) -> ChargeSplit {
        match self.electrode {
            Electrode::None => ChargeSplit {
                ratio: 0.0,
                conducting: false,
            },
            Electrode::ConductingCharge { .. } | Electrode::ConductingPotential { .. } => {
                ChargeSplit {
                    ratio: self.compliance.charge_per_force(),
                    conducting: true,
                }
            }
            Electrode::Insulating => ChargeSplit {
                ratio: 0.0,
                conducting: false,
            },
        }
    }

    /// `Y* = y22 + χ y23` (1/Pa).
    pub fn pressure_compliance(&self, split: ChargeSplit) -> f64 {
        let y23 = self.compliance.electric.map_or(0.0, |e| e.y23);
        self.compliance.y22 + split.ratio * y23
    }

    /// The pressure per unit of the collocation grid's unit response, `h''/Y*` (1/Pa·m): the
    /// pressure equation's right-hand side for a profile of constant curvature.
    pub fn pressure_scale(&self, split: ChargeSplit) -> f64 {
        self.profile.pressure_scale(self.pressure_compliance(split))
    }

    /// κ of the pressure equation (zero under Goodman's approximation).
    pub fn pressure_shear_coupling(&self, split: ChargeSplit) -> f64 {
        match self.coupling {
            Coupling::Goodman => 0.0,
            Coupling::Full if split.conducting => self.compliance.pressure_shear_coupling(),
            Coupling::Full => self.compliance.w12,
        }
    }

    /// Local coefficient of p in `−∂ux/∂x`: `w12 + χ w13`.
    pub fn local_pressure_strain(&self, split: ChargeSplit) -> f64 {
        self.compliance.w12 + split.ratio * self.compliance.electric.map_or(0.0, |e| e.w13)
    }

    /// Charge Γ1 = kP carried by the pressure under a conducting punch (C/m).
    pub fn pressure_charge(&self, normal_load: f64) -> f64 {
        self.compliance.charge_per_force() * normal_load
    }
}

/// One admissibility check: `(name, measure, allowed, reported value, x)`; it fails when
/// `measure > allowed`.
pub(crate) type Check<'a> = (&'a str, f64, f64, f64, f64);

/// The first failed check as an [`SolveFailure::Inadmissible`] error.
///
/// [`SolveFailure::Inadmissible`]: crate::error::SolveFailure::Inadmissible
pub(crate) fn first_violation(checks: &[Check<'_>]) -> Result<(), crate::error::SolveFailure> {
    match checks.iter().find(|c| c.1 > c.2) {
        Some(&(name, _, _, value, x)) => Err(crate::error::SolveFailure::Inadmissible {
            check: name.to_string(),
            value,
            x,
        }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use crate::quadrature::BoundedSeries;

    use super::*;

    /// The series `scale Σ (−1)^k U_{k−1}/k²`, k = 1..n: coefficients decaying only like
    /// 1/k², the tables' hard case.
    pub(super) fn alternating_series(n: usize, scale: f64) -> BoundedSeries {
        BoundedSeries {
            beta: (1..=n)
                .map(|k| scale * (-1f64).powi(k as i32) / (k * k) as f64)
                .collect(),
        }
    }

    /// The tests' chain: a normal-loading-like zone (`alternating_series` of `terms` terms and a
    /// centre kink) on [−0.95, 0.95], faded into the zone [−0.8, 0.4] with a series of its own
    /// and the given extras, as in the first tangential phase; the base tabulated with
    /// `base_nodes` points per piece when given.
    pub(super) fn faded_chain(
        terms: usize,
        base_nodes: Option<usize>,
        extras: Vec<(f64, f64, f64)>,
    ) -> StickZone {
        let base = std::sync::Arc::new(StickZone::new(
            -0.95,
            0.95,
            alternating_series(terms, 1.0),
            -0.3,
        ));
        if let Some(nodes) = base_nodes {
            base.tabulate(nodes);
        }
        let link = Inherited::new(base, Some((-0.8, -0.55)), Some((0.1, 0.4)));
        StickZone {
            inherited: Some(std::sync::Arc::new(link)),
            extras,
            ..StickZone::new(-0.8, 0.4, alternating_series(terms, 0.5), 0.0)
        }
    }

    /// The largest `|got − want|` over `points`, relative to the largest `|want|`.
    pub(super) fn worst_relative(
        points: &[f64],
        got: impl Fn(f64) -> f64,
        want: impl Fn(f64) -> f64,
    ) -> f64 {
        let scale = points.iter().map(|&x| want(x).abs()).fold(0.0, f64::max);
        points
            .iter()
            .map(|&x| (got(x) - want(x)).abs() / scale)
            .fold(0.0, f64::max)
    }
}
