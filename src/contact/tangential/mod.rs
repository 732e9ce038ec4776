//! One step of a tangential phase: forward slip (`dQ > 0`) or reverse slip (`dQ < 0`) at
//! prescribed Q, with the stored memory (seed Section 4, eqs. 43–63).
//!
//! # Equations
//! In a phase with slip sign `s = ±1` both slip zones carry `q = s η p` (the traction on the
//! half-plane points along the motion of the punch), and on the stick zone `[lo, hi]`
//! `q = s η p + q̃` with q̃ bounded at both ends (seed eqs. 44 and 61: `q** = q − ηp`,
//! `q*** = q + ηp`, here one formula for both signs). Eq. (A) with the remembered strain m(x)
//! gives (seed eqs. 43/60, with N2/N3 written out)
//!
//! ```text
//! y11 H'q̃ = m(x) + (w12 + χ w13) p + w13 w − s η y11 H'p,      lo ≤ x ≤ hi
//! ∫ q̃ dx = Q − s η P                                            (seed eqs. 48/63)
//! ```
//!
//! The stick-zone ends are the unknowns a time-stepping driver needs (the seed paper instead
//! fixes one end and computes Q, eqs. 58–59): the consistency residual (seed eq. 35's analogue,
//! the `(M+1)`-th equation of eq. 58) and the force residual fix them, while the pressure (with
//! the eccentric punch, seed eqs. 46, 52, 54) gives its own consistency and resultant for a and
//! c; the charge follows eqs. 47, 53, 55.
//!
//! The implementation solves for the four geometric unknowns `(lo, hi, a, c)` together, by a
//! quasi-Newton method: within a phase the Jacobian is built by finite differences on a
//! coarse companion grid at the step's first iterate (`coarse_jacobian`; where the grid has
//! none, it is carried over from the previous step), at a phase start and whenever a
//! quasi-Newton direction fails the line search by finite differences on the grid itself,
//! and it is improved by a rank-one secant update after every accepted iterate: within a
//! phase the projected one, which keeps the secant conditions of the attempt's earlier steps
//! (`SecantDirections`), at a phase start Broyden's.
//! Each residual evaluation solves the linear problem at fixed geometry (pressure, charge and
//! stick traction coupled through κq, w13 w and the slip traction) by a fixed-point iteration
//! on the shear traction at the pressure and charge collocation points, with Anderson
//! acceleration; the parts that depend only on the geometry (the remembered strain, the
//! inherited correction and its Cauchy transform, the slip-shape function, and the matrices
//! that map series coefficients to values at the other unknowns' points, `InnerMaps`) are
//! built once per evaluation, so that a pass of the iteration is two matrix sweeps (the stick
//! rows of p, w and `H'p` from one matrix of `T_n` values applied to two coefficient vectors,
//! and q̃'s own rows at the sample points) and five fast cosine and sine transforms (the
//! collocation solves and the pressure at the collocation points, which are Chebyshev
//! transforms over the grids' points, [`crate::quadrature`]). The inner iteration starts from
//! the previous iterate's coefficients and is solved only as far as the outer iteration needs:
//! to 1e−3 of the residual being reduced (an inexact Newton method, `inner_tolerance`), and
//! to 1e−14 for the residual that is accepted; a trial iterate from a residual within 1e4 of
//! the solver's tolerance is solved to 1e−14 at once, so that when it lands below the
//! tolerance it is accepted without a second, confirming evaluation. When no attempt of a step
//! converges, the first admissible iterate whose residual stalled below
//! `SlipOptions::stall_tolerance` is accepted (and ends the search) and keeps its residual in
//! the step record.
//! A step may be started from a recalled earlier step instead ([`Recalled`]: the same load in
//! a phase of the same direction that began from the same turning state). It is continued
//! only when its first residual, solved at the full inner tolerance, is below
//! `RECALL_RESIDUAL`; it is accepted by the same tolerance and checks as any other step,
//! except that a step accepted at the recalled geometry to the bit from the recalled step's
//! start state takes that step's checks and φ0 (`Recalled::admissibility`): its states are
//! the recalled step's to the tolerance.
//! An attempt that stalls from a carried or coarse Jacobian is made once more from a
//! finite-difference one before its stalled iterate is taken. Where another solver takes the
//! steps this one fails (`numerics.solver = auto`), a step's attempts together make at most
//! `SlipOptions::step_evaluations` residual evaluations: a step that fails would otherwise
//! make its whole attempt plan, which grows with the stick ends the memory remembers.
//! (Block Gauss–Seidel between the stick ends and (a, c), as in the seed paper, falls into
//! 2-cycles when the contact shifts at a reversal.)
//!
//! # Inherited corrections
//! The memory has square-root kinks at the ends of earlier stick zones (the exterior Cauchy
//! transform of their bounded corrections). Inside a new stick zone such a kink spoils the
//! spectral accuracy (overshoot of |q|/ηp by 2 % at M = 64). Each new zone therefore carries the
//! correction of the zone that began the phase in closed form ([`super::Inherited`], faded out
//! where the new zone ends inside the old one), and solves only for the smooth remainder. In
//! the uncoupled limit this reproduces Cattaneo–Mindlin–Deresiewicz–Masing histories to
//! round-off. An accepted zone drops an own correction that is round-off; the zones a phase
//! inherits from (its base chain) carry their `H'q̃` and q̃ tabulated piecewise
//! (`StickZone::tabulate`); a zone that carries nothing of its own is skipped when a
//! later zone inherits it, so a steady history's chains stop growing.
//!
//! # Kinks at the stick ends
//! q̃ starts like a square root at each stick end, `q̃ ≈ k √(distance)`. Through κq (pressure
//! equation, module docs of [`super`]) and `w13 q` (charge equation) that one-sided root puts
//! square-root kinks into p and w; a series over the whole contact represents an interior
//! kink only algebraically, with an error that depends on where the kink falls between the
//! nodes (stick ends scattered by 2e−4 a among M = 192 … 512, see `docs/performance.md`). The
//! kinks are therefore carried in closed form ([`super::Kinks`]): a half-ellipse from the kink
//! point to the contact end on its slip side, `A √(distance)` near the point. The local
//! problem fixes A. Near the right end hi, with `α = κηs/Y*` (s the slip sign beside the end),
//! write p ≈ `A √(x − hi)₊ + P √(hi − x)₊`; since `H'` maps `√(x − hi)₊` to `−√(hi − x)₊` and
//! `√(hi − x)₊` to `√(x − hi)₊` (plus smooth terms), the pressure equation
//! `H'p + α p = −x/(RY*) − (κ/Y*) q̃` gives `P + αA = 0` and `−A + αP = −(κ/Y*) k`:
//!
//! ```text
//! A = ±(κ/Y*) k/(1 + α²)      (+ at a right end, − at a left end),   P = −αA (not carried)
//! B = ±(w13/y33)(k ∓ (κ/Y*) η² s² A)   for w (its equation has no w term; q carries ηs p)
//! ```
//!
//! (`P`, the 4 % root of p on the stick side, and the departure of the true exponent from ½
//! are left to the series; that exponent is ½ ∓ γ at a right end next to slip of sign ±1
//! (mirrored at a left end), γ the contact ends' (`docs/performance.md`, "Every step against
//! M = 2048").) k itself is read off q̃ inside each end (`EndProbes`: Richardson's
//! extrapolation of `q̃/√r` from `r = 0.01 h` and `0.02 h`, h the stick half-width, own series
//! plus inherited part; nearer the end where a remembered stick end lies within `0.04 h`, so
//! that the probes do not straddle its root); the series' end value `ψ(±1)` would be the
//! exact limit but is ill-conditioned. The new ends' two k are unknowns of the inner
//! iteration; a term on a stretch the grid does not resolve is switched off smoothly
//! (`resolved`).
//!
//! Remembered stick ends inside the new zone keep their kinks: near such a point x0 the
//! increments since the turning point solve homogeneous equations, so p, w and q keep the
//! turning state's kinks. The zone stores its roots `k` and slip signs (`StickZone::end_roots`,
//! `end_signs`); a later zone adds p and w terms at every remembered end inside it
//! (`Inherited::interior_roots`) with the stored k, their values at the stick points in the
//! local terms of the stick equation, and to q̃ the root that the friction part no longer
//! carries when the slip sign at x0 changed: `(S_old − S_new) η A √(distance)` on the far side
//! of x0, as the half-ellipse from x0 to the new stick end (`StickZone::extras`; a zone that
//! inherits one which already carries part of it adds only the difference,
//! `RememberedRoot::carried_sign`).
//!
//! With the kinks in closed form the stick ends and the friction work converge about ten times
//! faster in M (`docs/performance.md`, "Convergence in M").
//!
//! # States beyond the seed paper's form
//! - Right after a reversal in a coupled contact the contact shifts, and one edge may keep its
//!   old slip direction for a while: states with slip signs `(−s, s)` and `(s, −s)` are tried
//!   when `(s, s)` has no solution. The edge that keeps its old direction slips over a thin
//!   zone (1.6e−3 a at the first reversal of the default history), so after a phase that
//!   began mixed, a phase start tries that pattern (after the standard one) with that end as
//!   far from its contact end as it was then ([`PhaseStart`]).
//! - Stick ends can jump when the load passes an earlier turning point (Masing memory) or when
//!   a plateau of the traction reaches the friction limit: the earlier stick/slip boundaries of
//!   the memory are tried as starting points.
//! - Masing's memory: when the load returns to the load of a remembered turning point whose
//!   stick zone lies inside the current one, the turning state solves the step again, and the
//!   stretch between the current stick ends and the remembered ones is exactly at the friction
//!   limit. The residuals are flat in the stick ends over that stretch (measured at the −½ηP
//!   arrivals of the PZT-4 default history: `|q|/(ηp) − 1` within ±5.5e−4 at M = 48 and ±8e−7
//!   at M = 96 over 0.27a when the stretch is labelled stuck), so the continuation from the
//!   previous step lands on an M-dependent point of it or stalls. The turning state is tried
//!   first (`masing_return`): the canonical stick zone is the smallest, the points at the
//!   limit being reported as slipping. In coupled contacts the reverse slip zones reach into
//!   the previous stick zone, so the steady ±Qmax states keep the memory of the first loading
//!   and are not mirror images of each other (they are for β = 0).
//!
//! # Checks
//! `p ≥ 0`; `|q| ≤ ηp` on the stick zone; and in each slip zone the slip increment since the
//! previous step, `Δs(x) = ∫ from the stick end to x of (ε_new − ε_old)`, must oppose the
//! friction on the half-plane, `s Δs ≤ 0`, i.e. friction must dissipate: the measure is the
//! frictional work density `s η p Δs` at six points of each zone (¼, ½, ¾, 0.9, 0.97 of the way
//! to the contact end, and the end), relative to its largest magnitude. Weighting by p leaves
//! out what the friction law leaves out: at a contact end p = 0, and next to a receding end
//! the strain change is singular (the pressure is released as points leave the contact), so
//! the pointwise sign of Δs in the last few per mille of a zone says nothing about friction
//! (measured: Figure-3 history at M = 96, or η = 0.2, 0.4: Δs changed sign within 7e−5 a of the
//! receding end, with the frictional work there below 1e−2 of the largest).

mod accelerations;
mod checks;
mod inner;
mod kinks;
mod linalg;
mod residual;
mod search;

pub use accelerations::Accelerations;
#[cfg(feature = "internals")]
pub use checks::assess_step;
pub use search::solve_slip;

use residual::Geometry;

use std::sync::Arc;

use serde::Serialize;

use super::ContactState;

/// Options of a tangential step.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct SlipOptions {
    /// Tolerance on the norm of the four dimensionless residuals (default 1e−11).
    ///
    /// Chosen against the discretisation error, which it must not touch: over the 22-run
    /// regression batch of `docs/performance.md` (M = 64 … 256, coupled and uncoupled, many
    /// cycles, variable amplitude) the states at 1e−11 agree with those at 1e−13 to 8.2e−11 a
    /// in the geometry and 4.7e−10 of the largest step dissipation (every slip sign the same;
    /// the step accepted at a stalled residual excepted), against discretisation errors of
    /// 1e−5–1e−4 a at M = 64 … 128; the batch takes 7713 residual evaluations instead of 8695
    /// (with the trial iterates near the tolerance solved fully, module docs). Two solution
    /// paths to one state (mirror symmetry, Masing returns, halved load steps, the solver's
    /// options) agree to a few times the tolerance, and the tests bound them by ten times it.
    pub tolerance: f64,
    /// Maximum Newton iterations.
    pub max_iterations: usize,
    /// Maximum residual evaluations of one attempt (one sign pattern and starting guess);
    /// converging attempts need at most ~60 (measured: 56), attempts without a root wander for
    /// hundreds.
    pub max_evaluations: usize,
    /// Allowed violation of `|q| ≤ ηp` (relative to `η p0`) and of the slip direction
    /// (relative to the largest slip increment).
    pub admissibility: f64,
    /// Last resort when an attempt of a step does not converge to `tolerance`: its best
    /// iterate, if its residual stopped decreasing below this value and it passes the checks,
    /// is accepted, and the step's remaining attempts are not made; the step record keeps its
    /// residual and the run reports such steps. (Measured over 23 histories, in the two steps
    /// with such an iterate no later attempt converged, Newton's fallback included; the other
    /// attempts stalled on the same flat residual: 60 of them at 3.8–5.7e−7 at step 65 of a
    /// variable-amplitude PZT-4 history, whose first stalled state lies 1.8e−7 a from the one
    /// with the smallest residual, and 9.5e−7 a at step 47 of the insulating Figure-3
    /// history at η = 0.4. Those two histories took 18089 and 4485 residual evaluations with
    /// all the attempts, 2895 and 686 without.)
    /// Attempts stall where the residual is not smooth in the
    /// geometry at the level of the discretisation error, e.g. the first step after a reversal
    /// with an edge slip zone thinner than the grid spacing at the contact end (measured:
    /// 1.3e−5 for the insulating Figure-3 history at η = 0.4, M = 64). 1e−4 is ten times the
    /// measured stalls and of the order of the discretisation error of the residuals; the
    /// accepted state of that example differs from a converged one (found by an earlier build)
    /// by 1e−3 a in one stick end, the size of the discretisation error of the stick ends at
    /// M = 64 (convergence study in `docs/performance.md`), and the next step is unaffected.
    pub stall_tolerance: f64,
    /// When no attempt of the quasi-Newton iteration converges, make the attempts again with
    /// Newton's method (finite-difference Jacobians at every iterate), which finds roots near
    /// the jumps to remembered boundaries that the quasi-Newton iteration can miss. Off where
    /// another solver takes the steps this one fails (`numerics.solver = auto`): a step that
    /// fails both ways costs about twice the evaluations of its quasi-Newton attempts.
    pub newton_fallback: bool,
    /// The most residual evaluations a step may make over all its attempts (the recalled
    /// step, Masing's return, the attempt plan, a retry from a fresh Jacobian, Newton's
    /// fallback), counted on the step's own grid as [`SlipStep::newton_iterations`] counts
    /// them (the coarse grid's Jacobians not counted); `None` (the default): no bound, every
    /// attempt of the plan is made. Once the bound is reached, the attempt under way stops at
    /// its next iterate (unless that iterate has converged), and no further attempt is made
    /// once one has failed: the failure reported is the first attempt's, as without the
    /// bound. Set where another solver takes the steps this one fails
    /// ([`Self::STEP_EVALUATIONS_BEHIND_ANOTHER_SOLVER`]).
    pub step_evaluations: Option<usize>,
    /// The speed-ups that carry information from one evaluation or step to the next
    /// ([`Accelerations`]; all on by default, [`Accelerations::none`] for the reference path).
    pub accelerations: Accelerations,
}

impl Default for SlipOptions {
    fn default() -> Self {
        Self {
            tolerance: 1e-11,
            max_iterations: 50,
            max_evaluations: 60,
            admissibility: 1e-3,
            stall_tolerance: 1e-4,
            newton_fallback: true,
            step_evaluations: None,
            accelerations: Accelerations::default(),
        }
    }
}

impl SlipOptions {
    /// The bound on a step's residual evaluations ([`Self::step_evaluations`]) where the
    /// general solver takes the steps this one fails (`numerics.solver = auto`).
    ///
    /// Chosen above every step that converged in the runs measured, and far below what the
    /// steps that fail take on a long history. Over the scenario files (the 15 in `scenarios/`
    /// and the default run: 781 steps and take-back tries) and five runs of
    /// `docs/failure_map.md` (the one `auto` did not complete, its first 300 s, and four that
    /// took 30–120 s: 2,299 more), 2,817 converged with at most 570 evaluations (median 4,
    /// 99th percentile 214, 99.9th 462; the scenario files' at most 82), the largest after
    /// seven or eight failed attempts. The 263 that failed took 202–10,509 (median 668),
    /// 329,178 evaluations in all against 30,796 for the ones that converged; in the run that
    /// did not complete, 32 failed steps took 540–10,509 each (up to 171 attempts: its memory
    /// holds many stick ends, and the plan tries pairs of them), 280 s of its 300 s. A bound
    /// of 600 keeps every converged step of those runs, so they take the same steps to the
    /// bit; 500 would have handed two of them to the general solver, 300 seventeen.
    pub const STEP_EVALUATIONS_BEHIND_ANOTHER_SOLVER: usize = 600;
}

/// Worst violations of the step's admissibility checks (≤ 0 when admissible).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct StepAdmissibility {
    /// `max (|q| − ηp)/(η p0)` on the stick zone.
    pub stick_excess: f64,
    /// `max s p Δs / max |p Δs|` over the sample points of the slip zones (module docs).
    pub slip_reversal: f64,
    /// `min p/p0`.
    pub min_pressure: f64,
    /// Where each measure is worst (m): stick excess, slip reversal, pressure (not written).
    #[serde(skip)]
    pub worst_at: [f64; 3],
}

/// A solved step.
#[derive(Debug, Clone, Serialize)]
pub struct SlipStep {
    /// The new state.
    pub state: ContactState,
    /// (Quasi-)Newton iterations of the accepted attempt.
    pub iterations: usize,
    /// Residual evaluations of the accepted attempt (each a coupled linear solve at fixed
    /// geometry), including those of finite-difference Jacobians.
    pub newton_iterations: usize,
    /// Final residual norm.
    pub residual: f64,
    /// The checks.
    pub admissibility: StepAdmissibility,
    /// The (quasi-Newton) Jacobian of the residuals with respect to `(lo, hi, a, c)` at the
    /// end, a starting Jacobian for the next step.
    #[serde(skip)]
    pub jacobian: [[f64; 4]; 4],
    /// Whether the step is a recalled step again (accepted at its geometry to the bit, from
    /// its start: [`Recalled::admissibility`]), whose checks and φ0 it took.
    #[serde(skip)]
    pub repeated: bool,
}

/// Which way the two slip zones slip: the states the spectral solver moves between, tried in
/// the order of its attempt plan. `q = ηp·s` in a slip zone with sign `s`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SlipPattern {
    /// Both zones with a load that increases: s = +1 at both edges.
    Forward,
    /// Both zones with a load that decreases: s = −1 at both edges.
    Reverse,
    /// Inward friction at both edges: s = +1 on the left, −1 on the right (a reversal in a
    /// coupled contact, one edge still slipping the old way).
    Inward,
    /// Outward friction at both edges: s = −1 on the left, +1 on the right.
    Outward,
}

impl SlipPattern {
    /// Both zones slipping with a load change of sign `sign`.
    pub fn with_load(sign: f64) -> Self {
        if sign > 0.0 {
            Self::Forward
        } else {
            Self::Reverse
        }
    }

    /// The pattern of the slip signs `(left, right)` (each ±1).
    pub fn of_signs((left, right): (f64, f64)) -> Self {
        match (left > 0.0, right > 0.0) {
            (true, true) => Self::Forward,
            (false, false) => Self::Reverse,
            (true, false) => Self::Inward,
            (false, true) => Self::Outward,
        }
    }

    /// The slip signs `(left, right)`.
    pub fn signs(self) -> (f64, f64) {
        match self {
            Self::Forward => (1.0, 1.0),
            Self::Reverse => (-1.0, -1.0),
            Self::Inward => (1.0, -1.0),
            Self::Outward => (-1.0, 1.0),
        }
    }
}

/// What a step passes to the next one of the same phase: its slip signs and Jacobian.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, serde::Deserialize)]
pub struct WarmStart {
    /// Slip signs of the left and right slip zones.
    pub signs: (f64, f64),
    /// Jacobian of the residuals with respect to `(lo, hi, a, c)`.
    pub jacobian: [[f64; 4]; 4],
}

/// How the last phase that began with mixed slip signs began (one edge kept its old slip
/// direction while the contact shifted, module docs): the signs, and the distance of the
/// stick end next to the edge that slipped against the phase from that contact end, relative
/// to the half-width. A later phase start tries that pattern ([`solve_slip`]) after the
/// standard pattern's attempts and before the other mixed ones, from the standard guess with
/// the end next to the edge that slips against the new phase (the other edge, when the
/// direction is the other one) moved to the same distance from its contact end.
///
/// The standard pattern keeps going first: where both converge to states that pass the checks
/// (an edge zone thinner than the checks resolve), the standard one is the state reported, as
/// without this guess (a PZT-4 history 0 → 0.2 → 0.6 → −0.2 → 0.4 ηP at M = 64: at −0.2 ηP the
/// mixed pattern tried first gave a state 1e−2 a away in one stick end, which also passes).
///
/// Measured on the default history at M = 128: at the first step after the turning point at
/// +½ηP the standard pattern converges to a state that fails the slip check (11 evaluations),
/// and the mixed one, from the standard guess 1.0e−2 a inside the left contact end while its
/// solution lies 1.6e−3 a inside, takes 20 evaluations; the two later reversals solved afresh
/// (at −½ηP and +½ηP) took 11 evaluations each from that distance, against 31 and 21.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, serde::Deserialize)]
pub struct PhaseStart {
    /// Slip signs of the left and right slip zones.
    pub signs: (f64, f64),
    /// Distance of the stick end from the contact end on the side that slipped against the
    /// phase, over the half-width.
    pub edge: f64,
}

impl PhaseStart {
    /// The pattern of `state`, the first step of a phase with slip sign `sign`; `None` when
    /// both edges slip with the phase (the standard pattern, which is tried first anyway).
    pub fn of(state: &ContactState, sign: f64) -> Option<Self> {
        let zone = state.traction.stick.as_ref()?;
        let t = &state.traction;
        let (c, a) = (state.centre, state.half_width);
        let edge = if (t.left_sign - sign).abs() > 0.0 {
            (zone.lo - (c - a)) / a
        } else if (t.right_sign - sign).abs() > 0.0 {
            (c + a - zone.hi) / a
        } else {
            return None;
        };
        Some(Self {
            signs: (t.left_sign, t.right_sign),
            edge,
        })
    }

    /// The stick ends to start this pattern from in a phase of slip sign `sign`: `standard`
    /// with the end next to the edge that slips against the phase moved to the remembered
    /// distance from its contact end, of the half-width and centre `(a, c)`.
    fn guess(&self, sign: f64, (lo, hi): (f64, f64), (a, c): (f64, f64)) -> (f64, f64) {
        if (self.signs.0 - sign).abs() > 0.0 {
            (c - a + self.edge * a, hi)
        } else if (self.signs.1 - sign).abs() > 0.0 {
            (lo, c + a - self.edge * a)
        } else {
            (lo, hi)
        }
    }
}

/// The accepted state of the same step (the same load) in an earlier phase of the same
/// direction that began from the same turning state, with its slip signs and final Jacobian.
/// In a steady cycle the step's problem is that step's again, so its geometry solves it.
#[derive(Debug, Clone, Serialize, serde::Deserialize)]
pub struct Recalled {
    /// The earlier step's state.
    #[serde(with = "crate::shared")]
    pub state: Arc<ContactState>,
    /// Its slip signs and Jacobian.
    pub warm: WarmStart,
    /// Its admissibility, when this step begins from the state the earlier one began from
    /// (the caller's judgement; the driver's is that their geometries and slip signs agree to
    /// the bit). A step accepted at the recalled geometry is then the earlier step again, to
    /// the solver's tolerance: it takes these checks and the recalled state's charge and
    /// potential instead of evaluating them.
    pub admissibility: Option<StepAdmissibility>,
}

impl Recalled {
    /// The recalled admissibility, when geometry `g` is the recalled state's to the bit.
    fn repeated_at(&self, g: &Geometry) -> Option<StepAdmissibility> {
        let recalled = Geometry::of(&self.state)?;
        let same = g
            .values()
            .iter()
            .zip(recalled.values())
            .all(|(x, y)| x.to_bits() == y.to_bits());
        self.admissibility.filter(|_| same)
    }
}

#[cfg(test)]
mod tests {
    use std::cell::RefCell;

    use super::inner::InnerMaps;
    use super::residual::StepProblem;
    use super::*;
    use crate::contact::pressure::Discretisation;
    use crate::contact::StickZone;

    /// One load step of scenario `sc` by the driver (`advance`, default options).
    pub(super) fn advance_driver(
        sc: &crate::scenario::Scenario,
        disc: &Discretisation,
        driver: &mut crate::history::DriverState,
        point: crate::history::LoadPoint,
    ) {
        let mut observer = crate::history::NoObserver;
        crate::history::advance(
            &sc.model,
            disc,
            driver,
            point,
            SlipOptions::default(),
            &mut observer,
        )
        .unwrap();
    }

    /// The forward-slip problem (both slip zones positive) of the default scenario `sc` at the
    /// driver's state, inheriting from `base`, with the given maps and caches.
    pub(super) fn forward_problem<'a>(
        sc: &'a crate::scenario::Scenario,
        disc: &'a Discretisation,
        driver: &'a crate::history::DriverState,
        base: Option<&'a Arc<StickZone>>,
        maps: &'a RefCell<InnerMaps>,
    ) -> StepProblem<'a> {
        StepProblem {
            model: &sc.model,
            disc,
            memory: &driver.memory,
            base,
            signs: (1.0, 1.0),
            normal_load: sc.normal_load,
            tangential_load: driver.state.tangential_load,
            scratch: maps,
            accelerations: Accelerations::default(),
            evaluations: None,
        }
    }

    /// A phase start's pattern remembers the distance of the stick end from the contact end on
    /// the side that slipped against the phase, and puts the end of a later guess at that
    /// distance on the side against that later phase (the other side in the other direction).
    #[test]
    fn phase_starts_remember_the_edge_that_slipped_against_the_phase() {
        use crate::contact::normal::{NormalOptions, solve_normal};
        let sc = crate::scenario::default_scenario();
        let disc = Discretisation::new(16);
        let mut state = solve_normal(&sc.model, &disc, sc.normal_load, NormalOptions::default())
            .unwrap()
            .state;
        (state.half_width, state.centre) = (2.0, 0.5);
        let zone = state
            .traction
            .stick
            .as_mut()
            .expect("frictional normal loading");
        (zone.lo, zone.hi) = (-1.4, 2.0);
        (state.traction.left_sign, state.traction.right_sign) = (1.0, -1.0);
        // Reverse slip (s = −1) with the left edge still slipping forward: its stick end lies
        // 0.1 inside the left contact end at −1.5, 0.05 a.
        let start = PhaseStart::of(&state, -1.0).expect("mixed");
        assert_eq!(start.signs, (1.0, -1.0));
        assert!((start.edge - 0.05).abs() < 1e-15, "{}", start.edge);
        // The same pattern in a forward phase has the right edge against it: the end moves
        // there, to the same distance from the contact end of the new (a, c).
        let (lo, hi) = start.guess(1.0, (-0.3, 0.7), (1.0, 0.0));
        assert_eq!(lo.to_bits(), (-0.3f64).to_bits(), "kept");
        assert!((hi - 0.95).abs() < 1e-15, "{hi}");
        let (lo, hi) = start.guess(-1.0, (-0.3, 0.7), (1.0, 0.0));
        assert!((lo + 0.95).abs() < 1e-15, "{lo}");
        assert_eq!(hi.to_bits(), 0.7f64.to_bits(), "kept");
        // As the start of a forward phase the same state slipped against it on the right, its
        // stick end 0.5 inside the right contact end at 2.5; with both edges slipping forward
        // it began in the standard pattern, which gives none.
        let forward = PhaseStart::of(&state, 1.0).expect("mixed");
        assert!((forward.edge - 0.25).abs() < 1e-15, "{}", forward.edge);
        state.traction.right_sign = 1.0;
        assert!(PhaseStart::of(&state, 1.0).is_none());
    }

    /// A recalled step's checks are taken only at its geometry to the bit, and only when the
    /// caller gave them (the step begins from the recalled step's start).
    #[test]
    fn recalled_checks_need_the_recalled_geometry() {
        use crate::contact::normal::{NormalOptions, solve_normal};
        let sc = crate::scenario::default_scenario();
        let disc = Discretisation::new(16);
        let normal =
            solve_normal(&sc.model, &disc, sc.normal_load, NormalOptions::default()).unwrap();
        let state = Arc::new(normal.state);
        let g = Geometry::of(&state).expect("frictional normal loading");
        let checks = StepAdmissibility {
            stick_excess: -0.25,
            ..StepAdmissibility::default()
        };
        let recalled = Recalled {
            state: Arc::clone(&state),
            warm: WarmStart {
                signs: (1.0, 1.0),
                jacobian: [[0.0; 4]; 4],
            },
            admissibility: Some(checks),
        };
        assert_eq!(recalled.repeated_at(&g), Some(checks));
        let next = |x: f64| f64::from_bits(x.to_bits() + 1);
        for moved in [
            Geometry {
                lo: next(g.lo),
                ..g
            },
            Geometry {
                hi: next(g.hi),
                ..g
            },
            Geometry { a: next(g.a), ..g },
            Geometry { c: next(g.c), ..g },
        ] {
            assert!(recalled.repeated_at(&moved).is_none());
        }
        let elsewhere = Recalled {
            admissibility: None,
            ..recalled
        };
        assert!(elsewhere.repeated_at(&g).is_none());
    }

    /// The contact integrals' rule (`contact_piece_nodes`: fewer nodes on the short pieces)
    /// gives `ux` at a point of the stick zone and δn as four times the whole rule on every
    /// piece does, to a small fraction of their ranges over the first two phases of the default
    /// history at M = 128 (at M ≤ 64 the rule is the whole rule).
    #[test]
    fn the_contact_rule_gives_the_displacements_to_a_small_error() {
        let sc = crate::scenario::default_scenario();
        let disc = Discretisation::new(128);
        let fine = 4 * crate::contact::field_rule_nodes(disc.nodes());
        let (mut rule, mut reference) = (Vec::new(), Vec::new());
        crate::history::walk_default_history(&disc, 30, |_, s| {
            // The contact centre at normal loading lies in every stick zone of these phases.
            rule.push(s.displacement_and_approach(&sc.model, 0.0));
            reference.push(s.displacement_and_approach_with(&sc.model, 0.0, |_, _| fine));
        });
        let range = |f: fn(&(f64, f64)) -> f64| {
            let v: Vec<f64> = reference.iter().map(f).collect();
            v.iter().copied().fold(f64::NEG_INFINITY, f64::max)
                - v.iter().copied().fold(f64::INFINITY, f64::min)
        };
        let worst = |f: fn(&(f64, f64)) -> f64| {
            rule.iter()
                .zip(&reference)
                .map(|(r, e)| (f(r) - f(e)).abs())
                .fold(0.0, f64::max)
        };
        let ux = worst(|v| v.0) / range(|v| v.0);
        let approach = worst(|v| v.1) / range(|v| v.1);
        println!("ux within {ux:.2e}, δn within {approach:.2e} of their ranges");
        // Measured 5.5e−9 and 5.3e−8 (δ's discretisation error at M = 128 is 1.5e−6 of its
        // range, against M = 256).
        assert!(ux > 0.0 && ux < 2e-8, "{ux:e}");
        assert!(approach < 2e-7, "{approach:e}");
    }
}
