//! A general element solver for the line contact after Kalker's method (J.J. Kalker,
//! *Three-dimensional elastic bodies in rolling contact*, 1990; E.A.H. Vollebregt's CONTACT):
//! every element of a band covering the contact is out of contact, stuck, or slipping either
//! way, as the solution decides. No zone structure is assumed, so extra stick and slip zones at
//! the contact ends (coupled contacts, varying loads) are represented.
//!
//! # Conventions
//! Those of [`crate::contact`]: x along the surface with the punch axis at x = 0, `p`
//! compressive positive, `q` the shear traction the punch exerts *on the half-plane* (so
//! `∫q = Q` is the tangential force on the punch), `g = −Dz(x, 0⁺)`, `uz` positive into the
//! solid. The punch has a rigid approach δz and a rigid tangential displacement δx, both
//! measured with the datum d of the logarithmic kernel (`model.reference_distance`).
//! The **slip** of a step is the displacement of the half-plane's surface relative to the
//! punch, `s = (ux − ux_prev) − (δx − δx_prev)`; Coulomb friction opposes it,
//! `q = −ηp sign(s)` where `s ≠ 0`. An element is [`ElementState::Stick`] when its slip in the
//! step is zero (to a relative 1e−10), also if `|q| = ηp` there.
//!
//! # Surface displacements (seed eqs. 11–13 integrated once)
//! With `(1/π)⨍ f(s)/(s − x) ds = (d/dx)[−(1/π)∫ f(s) ln(|x − s|/d) ds]` and
//! `f(x) = (d/dx)[½∫ f(s) sign(x − s) ds]`, eqs. (11)–(13) ([`crate::halfplane`]) integrate to
//!
//! ```text
//! ux(x) = −(w12/2) ∫p sign(x − s) ds − (w13/2) ∫g sign(x − s) ds − (y11/π) ∫q ln(|x − s|/d) ds
//! uz(x) =  (w12/2) ∫q sign(x − s) ds − (y22/π) ∫p ln(|x − s|/d) ds − (y23/π) ∫g ln(|x − s|/d) ds
//! φ(x)  =  (w13/2) ∫q sign(x − s) ds − (y23/π) ∫p ln(|x − s|/d) ds − (y33/π) ∫g ln(|x − s|/d) ds
//! ```
//!
//! up to constants, which the rigid-body unknowns δz, δx and φ0 absorb.
//!
//! # Elements
//! p, q and g are constant on each element of a [`Mesh`]; the contact conditions hold for the
//! element means (Galerkin). With element `i` = `[x1, x2]` and `j` = `[s1, s2]`,
//!
//! ```text
//! L_ij = ∫∫ ln(|x − s|/d) ds dx = G(x2 − s1) − G(x1 − s1) − G(x2 − s2) + G(x1 − s2),
//!        G(t) = t²/2 · ln(|t|/d) − 3t²/4      (G'' = ln(|t|/d), self term h²(ln(h/d) − 3/2))
//! S_ij = ∫∫ sign(x − s) ds dx = w_i w_j sign(i − j)           (w the element widths)
//! Z_i  = ∫ x²/(2R) dx = (x2³ − x1³)/(6R)
//! ```
//!
//! so that the element integrals of the displacements are `Ux = −(w12/2)S p − (w13/2)S g −
//! (y11/π)L q`, `Uz = (w12/2)S q − (y22/π)L p − (y23/π)L g`, `Φ = (w13/2)S q − (y23/π)L p −
//! (y33/π)L g`. Piecewise-constant elements make `p ≥ 0` and `|q| ≤ ηp` exact element by
//! element, and the Galerkin form makes `L` symmetric: `K = −(y11/π)L` is positive definite
//! when d exceeds the logarithmic capacity of the band (a quarter of its length), so the
//! tangential subproblem below is a strictly convex programme with an exact energy. The price
//! is first-order resolution of the contact and stick ends (each lies within an element);
//! graded meshes ([`Mesh::graded`], [`Mesh::symmetric`]) put small elements there.
//!
//! # Normal and electric subproblem (q fixed)
//! On the set C of contact elements, with unknowns `p_C`, `g_C`, δz and φ0:
//!
//! ```text
//! Uz_i − w_i δz + Z_i = 0          (zero gap, i ∈ C)
//! Φ_i − w_i φ0 = 0                 (conducting punch: constant potential, i ∈ C)
//! Σ w_j p_j = P,   Σ w_j g_j = Γ   (charge control; potential control fixes φ0 instead)
//! ```
//!
//! The insulating punch and the elastic half-plane have `g = 0` and no potential rows. Under
//! Goodman's approximation ([`Coupling::Goodman`]) the q terms are dropped from `Uz` and `Φ`.
//! C is found by Kalker's active set (NORM): solve on C; drop every element with `p < 0`; else
//! add every element outside C whose mean gap `(Uz_i − w_i δz + Z_i)/w_i` is negative (below
//! −1e−9 of the profile height at the contact end); stop when neither happens. A set met
//! before ends the search with the last set that had `p ≥ 0`.
//!
//! **Smooth contact ends.** When neither happens, the contact is then extended element by
//! element into its exterior neighbours for as long as the solution on the larger set keeps
//! `p ≥ 0` everywhere (and the gaps are checked again): C is the *largest* set with `p ≥ 0`
//! and no negative gap. For an elastic half-plane that set is the only one (the kernel is
//! positive definite), so nothing changes. Under a conducting punch with `Γ < Γ1 = kP` it is
//! not: the constant-potential charge `(Γ − kP)/(π√(a² − x²))` is negative and opens the gap
//! just outside each end like `+√(x − a)`, so a pressure with a positive inverse-square-root
//! end term, up to `A = −y23(Γ − kP)/Y*`, also leaves a non-negative gap (PZT-4, P = 2000 N/m,
//! Γ = 2e−7 C/m: A up to 285 N/m, any half-width from 0.926 to 1 times the smooth one). The
//! search above stops at the first such set it meets, so an advancing end stayed where it was
//! and the pressure piled up there (frictionless proportional loading ended at 0.927 a with
//! 0.9 p0 at the end elements; under tangential load the contact did not translate). The
//! model's closure is the seed paper's: p bounded, and for a smooth punch zero, at both ends,
//! which is A = 0, the largest of those sets, as the spectral solver assumes.
//!
//! # Tangential subproblem (p and g fixed)
//! With `U⁰` the element integrals of the previous step's `ux` (the slip reference; for an
//! element that enters the contact in the step, its `ux` at entry, module `entry`) and
//! `c = Ux(p, g) − U⁰`, the tractions minimise the incremental complementary energy
//!
//! ```text
//! J(q) = ½ qᵀK q + cᵀq   subject to   −ηp_i ≤ q_i ≤ ηp_i,   Σ w_i q_i = Q,
//! ```
//!
//! over the contact elements. Its KKT conditions are Coulomb's law: the multiplier of the
//! equality is the increment of δx, and `(∂J/∂q_i)/w_i − Δδx` is the element's mean slip,
//! zero where `|q_i| < ηp_i`, `≤ 0` where `q_i = ηp_i` and `≥ 0` where `q_i = −ηp_i`. It is
//! solved by the primal–dual active-set method (semismooth Newton on the complementarity
//! conditions), warm-started from the previous working set; if that does not settle in 30
//! iterations, by the primal active-set method, which decreases J monotonically and
//! terminates.
//!
//! **Prescribed displacement** ([`Drive::Displacement`]). When δx is given instead of Q, the
//! multiplier Δδx is known and moves into the linear term, and the equality goes:
//!
//! ```text
//! J(q) = ½ qᵀK q + (c − Δδx w)ᵀq   subject to   −ηp_i ≤ q_i ≤ ηp_i,
//! ```
//!
//! with the same KKT conditions (Coulomb's law, slip `(∂J/∂q_i)/w_i`) and Q = Σ w_i q_i a
//! result. The box alone always has a minimiser, also with every element at its bound: gross
//! slip, Q = ±ηP, where the displacement exceeds what the stick zone can hold.
//!
//! # Bulk stress
//! A bulk stress σB ([`Loads::bulk_stress`], tension positive) is a uniform `σxx = σB` of the
//! half-plane, the specimen's load in a fretting-fatigue test. It adds a uniform surface strain
//! `εB = s̃ σB` ([`crate::material::Material::bulk_compliance`]: `(1 − ν²)/E` for an isotropic
//! solid; for a piezoelectric one the open-circuit state `σzz = σxz = 0`, `Dz = 0`, whose
//! surface potential is uniform, so a conducting punch's condition is unchanged) and so the
//! displacement `ux = εB x` (x from the punch axis; the constant is the datum's, which δx
//! absorbs) to every point, and nothing to `uz` or φ on the surface:
//!
//! ```text
//! Ux_i += εB (x2² − x1²)/2
//! ```
//!
//! A change of σB in a step then moves the linear term `c` of the tangential programme by
//! `ΔεB ∫x dx` per element, so an element's slip increment gains `ΔεB x̄_i` (its centre
//! x̄_i) while δx keeps its meaning. The punch is rigid, so only the half-plane stretches: on
//! the uncoupled half-plane (ν = ½) a stick zone `|x − e| ≤ c` under Q with
//! `q = ηp0[√(1 − x²/a²) − (c/a)√(1 − (x − e)²/c²)]` has the q-part of its surface strain
//! `−y11 ηp0 e/a` uniform (`y11 = 2(1 − ν²)/E`), and stick (no change of strain since the
//! pressing) needs `y11 ηp0 e/a = εB`: `e = aσB/(2ηp0)`, towards +x for tension, half
//! Nowell and Hills' `aσB/(4ηp0)` for two similar elastic bodies, whose pad strains too
//! ([`crate::analytical::BulkStressCattaneo`]).
//!
//! # Alternation
//! When q changes p or g (`w12 ≠ 0`, or `w13 ≠ 0` under a conducting punch, and full
//! coupling), the two subproblems alternate until p and q change by less than
//! [`Options::tolerance`] (relative to max p and η max p). After [`Options::freeze_after`]
//! outer iterations elements may leave the contact but not enter it, so that an element at a
//! contact end cannot cycle between states; after [`Options::freeze_after_at_fixed_loads`]
//! in a step that keeps P and the electric load, whose contact moves only with q (about 0.2 a
//! per unit Q/P on PZT-4) and has it from the second outer iteration on. Above Γ1 a growth
//! of the contact by its negative gaps in the later iterations nearly always returns to the
//! set it began from (the overlap just outside the ends is the model's, "smooth contact
//! ends" above), at about six solves of the normal subproblem each, so the earlier freeze saves 13–23 % of such a step; the
//! default history's results are the same to 3e−13, and 100 random reversals under
//! `general` to 2e−4 in the dissipation of 50 phases and one element in the stick ends. A
//! step that changes P needs the later growth (the normal loading from the unloaded punch:
//! Spence's stick ratio extrapolated to 7e−4 with four iterations, 2e−3 with two).
//!
//! # Linear algebra
//! Both subproblems reduce to solves with `G = −L/π` on a set of elements: with
//! `Y = [y22 y23; y23 y33]` the normal and electric rows on C read `(Y ⊗ G_CC)(p; g) =
//! (b₁ + w δz; b₂ + w φ0)`, so `u = G⁻¹b₁`, `v = G⁻¹b₂` and `e = G⁻¹w` give δz and φ0 from the
//! resultant rows and then p and g in closed form; the tangential step on the free set F is
//! `d = λ K_FF⁻¹w_F − K_FF⁻¹∇_F`, `K = y11 G`, with λ from `w_Fᵀd = 0`. Each set has a
//! Cholesky factor (G is symmetric positive definite when d exceeds the band's logarithmic
//! capacity, as above), kept through the step's active-set changes: ordered with the
//! elements far from the middle of the set last, a change at the ends of the contact or of a
//! stick zone keeps the leading block and refactors only the trailing rows (`dense`).
//!
//! # Resolution
//! Contact and stick-zone ends lie within one element (a stick run ends at an element edge;
//! an element that a stick end crosses slips). The pressure converges at second order in the
//! element size away from the contact ends and at order ½ in the end element, where
//! `p ~ √(a − x)`. The elements that enter the contact in a step slip from their entry
//! (module `entry`), so proportional loading of an uncoupled contact sticks everywhere at
//! any step size; an element that a growing stick zone takes over in a step is still stuck
//! from the step's start, so path-dependent results (Spence's stick zone of incremental
//! normal loading) converge at first order in the load step.
//!
//! # State
//! [`GeneralState`] is plain data: the mesh, p, q, g, ux and the slip per element, the element
//! states, δz, δx, φ0 and the loads. It is the slip reference of the next step; the influence
//! matrices are rebuilt from the mesh by [`Solver::new`].

pub mod influence;
pub mod mesh;

mod dense;
mod entry;
mod handover;
mod normal;
mod recall;
mod remesh;
mod tangential;

#[cfg(test)]
mod tests;

use std::f64::consts::PI;

use faer::Mat;
use serde::{Deserialize, Serialize};

use super::{ContactModel, Coupling, Electrode};
use crate::error::SolveFailure;
use dense::Workspace;
use entry::Entry;
use influence::Influence;
pub use handover::PointLogs;
pub use mesh::{Focus, Mesh};
pub use recall::Recall;
use normal::{NormalInput, NormalSolution};
use tangential::{Bound, Programme};

/// State of one element after a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ElementState {
    /// Not in contact (p = 0).
    Exterior,
    /// In contact with no incremental slip in the step (also at `|q| = ηp` if the slip is zero).
    Stick,
    /// Slipping along +x relative to the punch (`q = −ηp`).
    SlipPositive,
    /// Slipping along −x relative to the punch (`q = +ηp`).
    SlipNegative,
}

/// The state after a step: plain data, the memory of the next step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GeneralState {
    /// The elements.
    pub mesh: Mesh,
    /// Pressure p per element (Pa).
    pub pressure: Vec<f64>,
    /// Shear traction q on the half-plane per element (Pa).
    pub shear: Vec<f64>,
    /// Surface charge g per element (C/m²; zero without a conducting punch).
    pub charge: Vec<f64>,
    /// Mean tangential surface displacement ux per element (m), datum d.
    pub displacement: Vec<f64>,
    /// Incremental slip of the last step per element (m): the half-plane's displacement
    /// relative to the punch, mean over the element.
    pub slip: Vec<f64>,
    /// Element states.
    pub codes: Vec<ElementState>,
    /// Rigid approach δz of the punch (m, into the solid), datum d.
    pub approach: f64,
    /// Rigid tangential displacement δx of the punch (m), datum d.
    pub shift: f64,
    /// Punch potential φ0 (V; zero without a conducting punch).
    pub potential: f64,
    /// The loads of the step.
    pub loads: Loads,
}

/// The loads of a step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Loads {
    /// P (N/m).
    pub normal: f64,
    /// Q (N/m).
    pub tangential: f64,
    /// Γ (C/m) for [`Electrode::ConductingCharge`], φ0 (V) for
    /// [`Electrode::ConductingPotential`], unused otherwise.
    pub electric: f64,
    /// The bulk stress σB (Pa, tension positive): a uniform σxx of the half-plane, the
    /// specimen's load in a fretting-fatigue test (module docs, *Bulk stress*). Absent from a
    /// serialised state where it is zero.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub bulk_stress: f64,
}

fn is_zero(value: &f64) -> bool {
    *value == 0.0
}

/// How the tangential loading of a step is prescribed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Drive {
    /// The tangential load Q of the step's [`Loads`]; δx is a result.
    Load,
    /// The rigid tangential displacement δx of the punch (m, datum d); Q is a result (the
    /// step's `Loads::tangential` is ignored and the new state's is `∫q`). It reaches ±ηP
    /// when every contact element slips one way: gross slip, a state like any other.
    Displacement(f64),
}

/// Options of a step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Outer iterations after which no element may enter the contact (the set may only
    /// shrink), so that a contact-end element cannot cycle.
    pub freeze_after: usize,
    /// The same for a step that keeps P and the electric load: its contact changes only by
    /// the coupling to q, which the second outer iteration already has to about 15 % (module
    /// docs, *Alternation*).
    pub freeze_after_at_fixed_loads: usize,
    /// Maximum outer iterations.
    pub max_outer: usize,
    /// Outer tolerance on the change of p (relative to max p) and q (relative to η max p).
    pub tolerance: f64,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            freeze_after: 4,
            freeze_after_at_fixed_loads: 2,
            max_outer: 60,
            tolerance: 1e-8,
        }
    }
}

/// What a step did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StepReport {
    /// Outer (normal–tangential) iterations.
    pub outer_iterations: usize,
    /// Active-set iterations of the last normal and tangential subproblems.
    pub normal_iterations: usize,
    /// See [`StepReport::normal_iterations`].
    pub tangential_iterations: usize,
    /// Final outer change.
    pub residual: f64,
    /// Whether the normal active set returned to an earlier set (the contact end then sits
    /// where the last admissible set put it).
    pub normal_cycled: bool,
    /// Solves of the last tangential programme for the slip reference of the elements that
    /// entered the contact (1 where none did, 0 on a frictionless contact).
    pub entry_passes: usize,
}

/// How the electric problem is posed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum ElectricControl {
    /// No charge on the contact (elastic solid, insulating punch).
    None,
    /// Conducting punch with charge Γ (C/m).
    Charge(f64),
    /// Conducting punch at potential φ0 (V).
    Potential(f64),
}

/// The coefficients the element equations use.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Coefficients {
    pub y11: f64,
    pub y22: f64,
    pub w12: f64,
    /// `(y23, y33, w13)` of a piezoelectric solid.
    pub electric: Option<(f64, f64, f64)>,
    /// Whether q enters the normal and electric equations (false: Goodman's approximation).
    pub coupled: bool,
    pub friction: f64,
    pub profile: crate::contact::Profile,
    /// The plane-strain compliance of a uniform bulk stress, `εB = s̃ σB` (1/Pa,
    /// [`crate::material::Material::bulk_compliance`]).
    pub bulk: f64,
}

/// The solver for one model and mesh: the influence matrices, built once.
#[derive(Debug, Clone)]
pub struct Solver {
    coefficients: Coefficients,
    electrode: Electrode,
    mesh: Mesh,
    influence: Influence,
    /// The datum d of the logarithmic kernel (m).
    reference_distance: f64,
    options: Options,
}

impl GeneralState {
    /// The unloaded state on a mesh.
    pub fn unloaded(mesh: Mesh) -> Self {
        let n = mesh.len();
        Self {
            mesh,
            pressure: vec![0.0; n],
            shear: vec![0.0; n],
            charge: vec![0.0; n],
            displacement: vec![0.0; n],
            slip: vec![0.0; n],
            codes: vec![ElementState::Exterior; n],
            approach: 0.0,
            shift: 0.0,
            potential: 0.0,
            loads: Loads {
                normal: 0.0,
                tangential: 0.0,
                electric: 0.0,
                bulk_stress: 0.0,
            },
        }
    }

    /// Maximal runs of elements with the same state: `(state, from, to)` (m).
    pub fn zones(&self) -> Vec<(ElementState, f64, f64)> {
        let mut out: Vec<(ElementState, f64, f64)> = Vec::new();
        for (i, &code) in self.codes.iter().enumerate() {
            let (x1, x2) = (self.mesh.edges[i], self.mesh.edges[i + 1]);
            match out.last_mut() {
                Some(last) if last.0 == code => last.2 = x2,
                _ => out.push((code, x1, x2)),
            }
        }
        out
    }

    /// The outer edges of the outermost contact elements `(lo, hi)` (m), if any is in contact.
    pub fn contact_extent(&self) -> Option<(f64, f64)> {
        let first = self
            .codes
            .iter()
            .position(|&c| c != ElementState::Exterior)?;
        let last = self
            .codes
            .iter()
            .rposition(|&c| c != ElementState::Exterior)?;
        Some((self.mesh.edges[first], self.mesh.edges[last + 1]))
    }

    /// Total length of the elements in a state (m).
    pub fn length_of(&self, state: ElementState) -> f64 {
        (0..self.mesh.len())
            .filter(|&i| self.codes[i] == state)
            .map(|i| self.mesh.width(i))
            .sum()
    }

    /// `∫p dx` (N/m), `∫q dx` (N/m) and `∫g dx` (C/m) by the element values.
    pub fn resultants(&self) -> (f64, f64, f64) {
        let w = self.mesh.widths();
        let dot = |v: &[f64]| v.iter().zip(&w).map(|(a, b)| a * b).sum::<f64>();
        (dot(&self.pressure), dot(&self.shear), dot(&self.charge))
    }
}

impl Solver {
    /// A solver for a model on a mesh. The datum d should exceed a quarter of the mesh's
    /// length, so that `−L` is positive definite: the tangential programme is strictly convex
    /// and the Cholesky factors of the subproblems exist (module docs).
    pub fn new(model: &ContactModel, mesh: Mesh, options: Options) -> Self {
        let c = &model.compliance;
        let electric = match model.electrode {
            Electrode::None => None,
            _ => c.electric.map(|e| (e.y23, e.y33, e.w13)),
        };
        let coefficients = Coefficients {
            y11: c.y11,
            y22: c.y22,
            w12: c.w12,
            electric,
            coupled: model.coupling == Coupling::Full,
            friction: model.friction,
            profile: model.profile.clone(),
            bulk: model.material.bulk_compliance(),
        };
        let influence = Influence::new(&mesh, model.reference_distance);
        Self {
            coefficients,
            electrode: model.electrode,
            mesh,
            influence,
            reference_distance: model.reference_distance,
            options,
        }
    }

    /// The mesh.
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }

    fn electric_control(&self, loads: Loads) -> ElectricControl {
        match (self.electrode, self.coefficients.electric) {
            (Electrode::ConductingCharge { .. }, Some(_)) => {
                ElectricControl::Charge(loads.electric)
            }
            (Electrode::ConductingPotential { .. }, Some(_)) => {
                ElectricControl::Potential(loads.electric)
            }
            _ => ElectricControl::None,
        }
    }

    /// Whether q changes p or g, so that the subproblems must be alternated.
    fn alternates(&self, control: ElectricControl) -> bool {
        let c = &self.coefficients;
        let w13 = match control {
            ElectricControl::None => 0.0,
            _ => c.electric.map_or(0.0, |e| e.2),
        };
        c.coupled && c.friction > 0.0 && (c.w12 != 0.0 || w13 != 0.0)
    }

    /// The frictionless half-width of the profile under the loads' P
    /// ([`crate::contact::Profile::frictionless_half_width`]: Hertz's for the cylinder), with
    /// the pressure compliance `Y* = y22` (no charge on the contact) or `y22 − y23²/y33` (a
    /// conducting punch): a first guess of the contact (m).
    pub fn first_half_width(&self, loads: Loads) -> f64 {
        let c = &self.coefficients;
        let ystar = match (self.electric_control(loads), c.electric) {
            (ElectricControl::None, _) | (_, None) => c.y22,
            (_, Some((y23, y33, _))) => c.y22 - y23 * y23 / y33,
        };
        c.profile.frictionless_half_width(loads.normal, ystar)
    }

    /// The mean gap between the punch and the surface over each element of a state,
    /// `(1/Δi)∫(uz − δz + x²/2R) dx` (m): ≥ 0 outside the contact where the state is
    /// admissible, and 0 on the contact elements (where the contact equations make it zero).
    pub fn gaps(&self, state: &GeneralState) -> Vec<f64> {
        let input = NormalInput {
            mesh: &self.mesh,
            influence: &self.influence,
            coefficients: &self.coefficients,
            shear: &state.shear,
            normal_load: state.loads.normal,
            electric: self.electric_control(state.loads),
            grow: false,
        };
        let contact: Vec<bool> = state
            .codes
            .iter()
            .map(|&c| c != ElementState::Exterior)
            .collect();
        normal::gaps(
            &input,
            (&state.pressure, &state.charge, state.approach),
            &contact,
        )
    }

    /// The state of a punch that has left the half-plane (P = 0): no contact, no traction or
    /// charge, and so an undeformed surface (`ux = 0`: the memory of the past is gone, and a
    /// contact made again sticks where it forms); δz = 0 (the surface is at its datum), δx
    /// `shift` (the punch may move while it is off), φ0 the prescribed potential of a
    /// potential-controlled punch and 0 otherwise.
    pub fn separated(&self, loads: Loads, shift: f64) -> GeneralState {
        let mut state = GeneralState::unloaded(self.mesh.clone());
        state.shift = shift;
        if let ElectricControl::Potential(potential) = self.electric_control(loads) {
            state.potential = potential;
        }
        state.loads = Loads {
            tangential: 0.0,
            ..loads
        };
        state
    }

    /// The contact elements of the start of a step: the previous contact, or the frictionless
    /// width with the pressure compliance of the electrode if there was none.
    fn initial_contact(&self, previous: &GeneralState, loads: Loads) -> Vec<bool> {
        let mut contact: Vec<bool> = previous.pressure.iter().map(|&p| p > 0.0).collect();
        if !contact.iter().any(|&c| c) {
            let a = self.first_half_width(loads);
            for (i, flag) in contact.iter_mut().enumerate() {
                let (x1, x2) = (self.mesh.edges[i], self.mesh.edges[i + 1]);
                *flag = x2.abs().min(x1.abs()) < a || (x1 <= 0.0 && x2 >= 0.0);
            }
        }
        contact
    }

    /// One load step from `previous` (its tractions and displacements are the slip reference)
    /// under the tangential load `loads.tangential`.
    pub fn step(
        &self,
        previous: &GeneralState,
        loads: Loads,
    ) -> Result<(GeneralState, StepReport), SolveFailure> {
        self.step_with(previous, loads, Drive::Load)
    }

    /// One step from `previous` to the normal and electric `loads` with the tangential
    /// loading prescribed by `drive`.
    pub fn step_with(
        &self,
        previous: &GeneralState,
        loads: Loads,
        drive: Drive,
    ) -> Result<(GeneralState, StepReport), SolveFailure> {
        self.step_to(previous, loads, drive, self.options.tolerance)
    }

    /// [`Solver::step_with`] with the outer iteration stopped at the change `tolerance`
    /// instead of [`Options::tolerance`] (a check that needs the tractions to less than its
    /// own bound, [`Recall::step_to_tolerance`]): with the alternation's contraction of about
    /// 0.15 an outer iteration, the state is then within about 0.2 `tolerance` of the
    /// converged one.
    fn step_to(
        &self,
        previous: &GeneralState,
        loads: Loads,
        drive: Drive,
        tolerance: f64,
    ) -> Result<(GeneralState, StepReport), SolveFailure> {
        assert_eq!(
            previous.mesh, self.mesh,
            "the state belongs to another mesh"
        );
        let control = self.electric_control(loads);
        let alternate = self.alternates(control);
        let mut contact = self.initial_contact(previous, loads);
        let mut q = previous.shear.clone();
        let mut p_old = previous.pressure.clone();
        let mut report = StepReport {
            outer_iterations: 0,
            normal_iterations: 0,
            tangential_iterations: 0,
            residual: 0.0,
            normal_cycled: false,
            entry_passes: 0,
        };
        let mut work = Workspace::default();
        let same = |a: f64, b: f64| a.to_bits() == b.to_bits();
        let fixed_loads = same(loads.normal, previous.loads.normal)
            && same(loads.electric, previous.loads.electric);
        let freeze_after = if fixed_loads {
            self.options.freeze_after_at_fixed_loads
        } else {
            self.options.freeze_after
        };
        for outer in 0..self.options.max_outer {
            let input = NormalInput {
                mesh: &self.mesh,
                influence: &self.influence,
                coefficients: &self.coefficients,
                shear: &q,
                normal_load: loads.normal,
                electric: control,
                grow: outer < freeze_after,
            };
            let normal = normal::solve(&input, contact, &mut work)?;
            let p_start = p_old.clone();
            contact = normal.contact.clone();
            let total = match drive {
                Drive::Load => Some(loads.tangential),
                Drive::Displacement(_) => None,
            };
            let shift = match drive {
                Drive::Load => 0.0,
                Drive::Displacement(at) => at - previous.shift,
            };
            let (q_new, tangential) = self.tangential(
                previous,
                &normal,
                (total, shift, loads.bulk_stress),
                (&q, &p_start),
                &mut work,
            )?;
            let pmax = normal.pressure.iter().cloned().fold(0.0, f64::max);
            let dq = q_new
                .iter()
                .zip(&q)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            let dp = normal
                .pressure
                .iter()
                .zip(&p_old)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            let change =
                (dp / pmax).max(dq / (self.coefficients.friction * pmax).max(f64::MIN_POSITIVE));
            report = StepReport {
                outer_iterations: outer + 1,
                normal_iterations: normal.iterations,
                tangential_iterations: tangential.iterations,
                residual: change,
                normal_cycled: report.normal_cycled || normal.cycled,
                entry_passes: tangential.entry_passes,
            };
            q = q_new;
            p_old.clone_from(&normal.pressure);
            if !alternate || (outer > 0 && change < tolerance) {
                let mut loads = loads;
                if total.is_none() {
                    loads.tangential = (0..q.len()).map(|i| q[i] * self.mesh.width(i)).sum();
                }
                return Ok((self.finish(previous, loads, normal, q, tangential), report));
            }
        }
        Err(SolveFailure::NoConvergence {
            what: "normal–tangential alternation",
            iterations: self.options.max_outer,
            residual: report.residual,
        })
    }
}

/// The most solves of the tangential programme for the slip reference of the elements that
/// enter the contact in a step (`entry`).
const ENTRY_PASSES: usize = 40;

/// The tangential subproblem's result on every element.
struct Tangential {
    slip: Vec<f64>,
    /// `None` out of contact.
    status: Vec<Option<Bound>>,
    shift: f64,
    tolerance: f64,
    iterations: usize,
    /// Solves of the programme for the entering elements' reference (1 without entry).
    entry_passes: usize,
}

impl Solver {
    /// The displacement `∫ux` per element of the pressure and charge (module docs, (U)) and
    /// of the bulk stress `bulk_stress` (module docs, *Bulk stress*).
    fn fixed_displacement(&self, pressure: &[f64], charge: &[f64], bulk_stress: f64) -> Vec<f64> {
        let n = self.mesh.len();
        let c = &self.coefficients;
        let mut sp = vec![0.0; n];
        self.influence.sign_apply(pressure, &mut sp);
        let mut out: Vec<f64> = sp.iter().map(|v| -0.5 * c.w12 * v).collect();
        if let Some((_, _, w13)) = c.electric {
            let mut sg = vec![0.0; n];
            self.influence.sign_apply(charge, &mut sg);
            for (o, v) in out.iter_mut().zip(&sg) {
                *o -= 0.5 * w13 * v;
            }
        }
        if bulk_stress != 0.0 {
            let strain = c.bulk * bulk_stress;
            for (i, o) in out.iter_mut().enumerate() {
                let (x1, x2) = (self.mesh.edges[i], self.mesh.edges[i + 1]);
                *o += strain * 0.5 * (x2 * x2 - x1 * x1);
            }
        }
        out
    }

    /// The tangential subproblem at the pressure and charge of `normal`, with the previous
    /// state's displacement as the slip reference, started from `start`, under the load Q
    /// (`total`) or, where that is `None`, the punch displacement increment `shift` (module
    /// docs: the multiplier of the equality, prescribed, moves into the linear term).
    fn tangential(
        &self,
        previous: &GeneralState,
        normal: &NormalSolution,
        (total, shift, bulk_stress): (Option<f64>, f64, f64),
        (start, start_pressure): (&[f64], &[f64]),
        work: &mut Workspace,
    ) -> Result<(Vec<f64>, Tangential), SolveFailure> {
        let n = self.mesh.len();
        let c = &self.coefficients;
        let act: Vec<usize> = (0..n).filter(|&i| normal.contact[i]).collect();
        let mut q = vec![0.0; n];
        let mut out = Tangential {
            slip: vec![0.0; n],
            status: (0..n)
                .map(|i| normal.contact[i].then_some(Bound::Free))
                .collect(),
            shift: 0.0,
            tolerance: 0.0,
            iterations: 0,
            entry_passes: 0,
        };
        if c.friction == 0.0 {
            if let Some(total) = total.filter(|&t| t != 0.0) {
                return Err(SolveFailure::NoAdmissibleState {
                    reason: format!("gross slip: Q = {total:.6e} N/m on a frictionless contact"),
                });
            }
            out.shift = shift;
            return Ok((q, out));
        }
        let fixed = self.fixed_displacement(&normal.pressure, &normal.charge, bulk_stress);
        // L on the contact elements (K = −(y11/π) L): a view of the mesh's matrix where they
        // are consecutive, as they are unless a ring has entered; else gathered, and kept
        // while the contact set stays.
        let consecutive = act.windows(2).all(|w| w[1] == w[0] + 1);
        let gathered = match work.gathered_log.take() {
            Some((set, l)) if set == act => Some(l),
            _ if consecutive => None,
            _ => Some(Mat::<f64>::from_fn(act.len(), act.len(), |r, s| {
                self.influence.log[(act[r], act[s])]
            })),
        };
        let l = match &gathered {
            Some(l) => l.as_ref(),
            None => {
                let first = act.first().copied().unwrap_or(0);
                (self.influence.log.as_ref()).submatrix(first, first, act.len(), act.len())
            }
        };
        let w: Vec<f64> = act.iter().map(|&i| self.mesh.width(i)).collect();
        let enters = (0..n).any(|i| normal.contact[i] && previous.codes[i] == ElementState::Exterior);
        let entry = if enters {
            let input = NormalInput {
                mesh: &self.mesh,
                influence: &self.influence,
                coefficients: &self.coefficients,
                shear: start,
                normal_load: previous.loads.normal,
                electric: self.electric_control(previous.loads),
                grow: false,
            };
            let now = (&normal.pressure[..], &normal.charge[..], normal.approach);
            let after = normal::gaps(&input, now, &normal.contact);
            let before = (work.previous_gaps).get_or_insert_with(|| self.gaps(previous));
            Entry::new(&self.mesh, previous, (before, &after), &normal.contact)
        } else {
            Entry::default()
        };
        let mut reference = previous.displacement.clone();
        // `ux_B(t1) − Δδx` of each ring's B, from where it was.
        let mut anchors: Vec<f64> = entry.outer().iter().map(|&b| previous.displacement[b]).collect();
        let bound: Vec<f64> = act
            .iter()
            .map(|&i| c.friction * normal.pressure[i])
            .collect();
        let mut begin: Vec<f64> = act.iter().map(|&i| start[i]).collect();
        // The working set of the start: elements at the friction limit of the start traction
        // and the previous pressure keep their bound.
        let mut begin_status: Vec<Bound> = act
            .iter()
            .map(|&i| {
                let u = c.friction * start_pressure[i];
                if u > 0.0 && start[i] >= u * (1.0 - 1e-9) {
                    Bound::Upper
                } else if u > 0.0 && start[i] <= -u * (1.0 - 1e-9) {
                    Bound::Lower
                } else {
                    Bound::Free
                }
            })
            .collect();
        // The slip reference of the elements entering the contact (`entry`), by a fixed-point
        // iteration on the displacement of the free elements next to the new contact ends.
        let mut m;
        let mut last: Option<tangential::Minimiser> = None;
        let first = (begin.clone(), begin_status.clone());
        let mut passes = 0;
        let mut secant: Option<(Vec<f64>, Vec<f64>)> = None;
        loop {
            entry.apply(previous, &anchors, &mut reference);
            let lin: Vec<f64> = act
                .iter()
                .zip(&w)
                .map(|(&i, w)| fixed[i] - (reference[i] + shift) * w)
                .collect();
            let programme = Programme {
                l,
                c: &lin,
                w: &w,
                bound: &bound,
                total,
                elements: &act,
                kernel: dense::Kernel {
                    log: &self.influence.log,
                    scale: -c.y11 / PI,
                },
            };
            // A later pass starts from the last one's solution; where its programme fails
            // from there, from the step's start; where that fails too, the step keeps the last
            // pass's solution, whose reference is that of the previous pass (at the first pass,
            // the step-start one).
            let solved = tangential::minimise(&programme, &begin, &begin_status, work).or_else(
                |e| match &last {
                    Some(_) => tangential::minimise(&programme, &first.0, &first.1, work),
                    None => Err(e),
                },
            );
            m = match (solved, last.take()) {
                (Ok(m), _) => m,
                (Err(_), Some(kept)) => {
                    m = kept;
                    break;
                }
                (Err(e), None) => return Err(e),
            };
            passes += 1;
            if entry.is_empty() {
                break;
            }
            let moved: Vec<f64> = entry
                .outer()
                .iter()
                .map(|&b| {
                    let lq: f64 = act
                        .iter()
                        .zip(&m.q)
                        .map(|(&j, q)| self.influence.log[(b, j)] * q)
                        .sum();
                    (fixed[b] - (c.y11 / PI) * lq) / self.mesh.width(b) - m.shift - shift
                })
                .collect();
            // Secant steps on g(a) = F(a) − a per anchor (F is affine while the working set
            // stays: one secant step then solves a ring alone); a plain step first.
            let residual: Vec<f64> = moved.iter().zip(&anchors).map(|(f, a)| f - a).collect();
            let change = residual.iter().fold(0.0_f64, |m, r| m.max(r.abs()));
            let next: Vec<f64> = (0..anchors.len())
                .map(|r| match &secant {
                    Some((a_old, g_old)) => {
                        let (a, g): (&Vec<f64>, &Vec<f64>) = (a_old, g_old);
                        let slope = (residual[r] - g[r]) / (anchors[r] - a[r]);
                        if slope.is_finite() && slope < -1e-3 {
                            anchors[r] - residual[r] / slope
                        } else {
                            moved[r]
                        }
                    }
                    None => moved[r],
                })
                .collect();
            secant = Some((anchors.clone(), residual));
            anchors = next;
            if change <= m.slip_tolerance {
                break;
            }
            if passes == ENTRY_PASSES {
                return Err(SolveFailure::NoConvergence {
                    what: "slip reference of the entering elements",
                    iterations: passes,
                    residual: change,
                });
            }
            begin.clone_from(&m.q);
            begin_status.clone_from(&m.status);
            last = Some(m);
        }
        work.gathered_log = gathered.map(|l| (act.clone(), l));
        for (r, &i) in act.iter().enumerate() {
            q[i] = m.q[r];
            out.slip[i] = m.slip[r];
            out.status[i] = Some(m.status[r]);
        }
        out.shift = m.shift + shift;
        out.tolerance = m.slip_tolerance;
        out.iterations = m.iterations;
        out.entry_passes = passes;
        Ok((q, out))
    }

    /// The new state from the converged subproblems.
    fn finish(
        &self,
        previous: &GeneralState,
        loads: Loads,
        normal: NormalSolution,
        shear: Vec<f64>,
        tangential: Tangential,
    ) -> GeneralState {
        let n = self.mesh.len();
        let c = &self.coefficients;
        let mut ux =
            self.fixed_displacement(&normal.pressure, &normal.charge, loads.bulk_stress);
        let mut lq = vec![0.0; n];
        self.influence.log_apply(&shear, &mut lq);
        for (i, u) in ux.iter_mut().enumerate() {
            *u = (*u - (c.y11 / PI) * lq[i]) / self.mesh.width(i);
        }
        let tol = tangential.tolerance;
        let codes = (0..n)
            .map(|i| {
                let s = tangential.slip[i];
                match tangential.status[i] {
                    None => ElementState::Exterior,
                    Some(Bound::Upper) if s < -tol => ElementState::SlipNegative,
                    Some(Bound::Lower) if s > tol => ElementState::SlipPositive,
                    Some(_) => ElementState::Stick,
                }
            })
            .collect();
        GeneralState {
            mesh: self.mesh.clone(),
            pressure: normal.pressure,
            shear,
            charge: normal.charge,
            displacement: ux,
            slip: tangential.slip,
            codes,
            approach: normal.approach,
            shift: previous.shift + tangential.shift,
            potential: normal.potential,
            loads,
        }
    }
}
