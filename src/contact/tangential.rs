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
//! finite-difference one before its stalled iterate is taken.
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

use std::cell::RefCell;
use std::collections::VecDeque;
use std::sync::Arc;

use serde::Serialize;

use crate::error::SolveFailure;
use crate::quadrature::{BoundedSeries, ColumnMatrix, RowMatrix, dot};

use super::memory::Memory;
use super::normal::arcsine_moment;
use super::pressure::{Discretisation, electric_resultants};
use super::{
    ContactModel, ContactState, Inherited, Kink, Kinks, StickZone, half_ellipse,
    half_ellipse_cauchy, kink_domain, smootherstep,
};

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
    /// Start a step from the same step of the last phase in the same direction that began
    /// from the same turning state, when there is one ([`Recalled`]; the history driver keeps
    /// them). In a steady cycle that state solves the step again, in one evaluation.
    pub recall: bool,
    /// Within a phase, start each attempt from the finite-difference Jacobian of the coarse
    /// companion grid ([`Discretisation::coarse`]) at its first iterate instead of the one
    /// carried from the previous step, or, for slip signs other than the previous step's,
    /// instead of a fine finite-difference one (where the grid has a coarse companion). The
    /// states are the same to the tolerance; the steps take fewer residual evaluations (the
    /// second step of a phase that began mixed, M = 128: 8 instead of 11).
    pub coarse_jacobian: bool,
    /// At a phase start, try the mixed slip pattern that began the last phase that began mixed
    /// (after the standard pattern's attempts, before the other mixed ones), from its stick end
    /// next to the edge that slipped against the phase ([`PhaseStart`]; the history driver
    /// keeps it). The states are the same to the tolerance; the later reversals of a coupled
    /// contact start their mixed attempt near their own state.
    pub mixed_start_guesses: bool,
    /// Within a phase, update the Jacobian by the projected secant update
    /// (`SecantDirections`) instead of Broyden's: each update keeps the Jacobian's action on
    /// the attempt's earlier step directions. The states are the same to the tolerance; the
    /// steps take fewer residual evaluations.
    pub projected_updates: bool,
}

impl Default for SlipOptions {
    fn default() -> Self {
        Self {
            tolerance: 1e-11,
            max_iterations: 50,
            max_evaluations: 60,
            admissibility: 1e-3,
            stall_tolerance: 1e-4,
            recall: true,
            coarse_jacobian: true,
            mixed_start_guesses: true,
            projected_updates: true,
        }
    }
}

/// Worst violations of the step's admissibility checks (≤ 0 when admissible).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct StepAdmissibility {
    /// `max (|q| − ηp)/(η p0)` on the stick zone.
    pub stick_excess: f64,
    /// `max s p Δs / max |p Δs|` over the sample points of the slip zones (module docs).
    pub slip_reversal: f64,
    /// `min p/p0`.
    pub min_pressure: f64,
    /// Where each measure is worst (m): stick excess, slip reversal, pressure.
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

/// The four geometric unknowns of a step: stick-zone ends and contact half-width and centre.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Geometry {
    lo: f64,
    hi: f64,
    a: f64,
    c: f64,
}

impl Geometry {
    /// A state's geometry (`None` without a stick zone).
    fn of(state: &ContactState) -> Option<Self> {
        let zone = state.traction.stick.as_ref()?;
        Some(Self {
            lo: zone.lo,
            hi: zone.hi,
            a: state.half_width,
            c: state.centre,
        })
    }

    fn values(&self) -> [f64; 4] {
        [self.lo, self.hi, self.a, self.c]
    }
}

/// Everything a step needs besides the geometry.
struct StepProblem<'a> {
    model: &'a ContactModel,
    disc: &'a Discretisation,
    memory: &'a Memory,
    base: Option<&'a Arc<StickZone>>,
    /// Slip signs of the left and right slip zones.
    signs: (f64, f64),
    normal_load: f64,
    tangential_load: f64,
    /// The last evaluation's [`InnerMaps`], whose matrices the next evaluation refills (one
    /// for all the attempts of a step).
    scratch: &'a RefCell<InnerMaps>,
    /// The inherited link of the last evaluation, whose fade table the next evaluation reuses
    /// when its ramps have hardly moved ([`Inherited::reusing_table_of`]; one for all the
    /// attempts of a step, on both grids).
    last_link: &'a RefCell<Option<Arc<Inherited>>>,
    /// The parts of the last evaluations that depend on the geometry through the stick
    /// points or through the sample points alone ([`Reused`]; one for all the attempts of a
    /// step, on both grids).
    reused: &'a RefCell<Reused>,
}

/// The fixed parts of recent evaluations that depend on only two of the four unknowns: `H'q̃`
/// of the chain and the remembered strain at the stick points (lo, hi), and S with the
/// inherited traction at the sample points (a, c). A finite-difference Jacobian moves one
/// unknown at a time, so two of its four evaluations find each part of its base point here
/// and skip the chain's sums (every output stays byte-identical, as it must). An
/// entry is taken only for the same grid, bit-identical points, the same inherited link (the
/// same `Arc`) and extras and the same slip signs (and stick ends, for a mixed state's S), so
/// what it holds is what the evaluation would compute, bit for bit. It lives for one
/// `solve_slip` call, whose attempts share one memory.
#[derive(Default)]
pub(super) struct Reused {
    stick: Vec<(PartsKey, Arc<StickParts>)>,
    samples: Vec<(PartsKey, Arc<SampleParts>)>,
}

/// `(H'q̃ of the chain, remembered strain)` at the stick points.
type StickParts = (Vec<f64>, Vec<f64>);

/// `(S, inherited traction)` at the pressure points and at the charge points.
type SampleParts = (Vec<(f64, f64)>, Vec<(f64, f64)>);

/// What an entry of [`Reused`] depends on: the grid's size, the interval the points are
/// mapped onto, the fixed part of q̃ (its inherited link, compared by identity, and its
/// extras), the slip signs, and for a mixed state's S the stick ends (else zero). The key
/// holds the link itself, so that no later link can take its address while the entry lives.
#[derive(Clone)]
struct PartsKey {
    nodes: usize,
    interval: [u64; 2],
    link: Option<Arc<Inherited>>,
    extras: Vec<[u64; 3]>,
    signs: [u64; 2],
    ends: [u64; 2],
}

impl PartialEq for PartsKey {
    fn eq(&self, other: &Self) -> bool {
        let same_link = match (&self.link, &other.link) {
            (Some(a), Some(b)) => Arc::ptr_eq(a, b),
            (None, None) => true,
            _ => false,
        };
        same_link
            && self.nodes == other.nodes
            && self.interval == other.interval
            && self.extras == other.extras
            && self.signs == other.signs
            && self.ends == other.ends
    }
}

impl PartsKey {
    fn new(nodes: usize, (centre, half): (f64, f64), closed: &StickZone, ends: [f64; 2]) -> Self {
        Self {
            nodes,
            interval: [centre.to_bits(), half.to_bits()],
            link: closed.inherited.clone(),
            extras: closed
                .extras
                .iter()
                .map(|&(u, v, a)| [u.to_bits(), v.to_bits(), a.to_bits()])
                .collect(),
            signs: closed.end_signs.map(f64::to_bits),
            ends: ends.map(f64::to_bits),
        }
    }
}

/// Entries kept of each kind: a finite-difference Jacobian's base point and its last moves.
const REUSED_ENTRIES: usize = 4;

impl Reused {
    /// The entry of `key` in `list`, or `make()` kept as the newest (the oldest dropped).
    fn get_or_make<T>(
        list: &mut Vec<(PartsKey, Arc<T>)>,
        key: PartsKey,
        make: impl FnOnce() -> T,
    ) -> Arc<T> {
        if let Some((_, parts)) = list.iter().find(|(k, _)| *k == key) {
            return parts.clone();
        }
        let parts = Arc::new(make());
        if list.len() == REUSED_ENTRIES {
            list.remove(0);
        }
        list.push((key, parts.clone()));
        parts
    }
}

impl StepProblem<'_> {
    fn valid(&self, g: &Geometry) -> bool {
        g.a > 0.0 && g.lo > g.c - g.a && g.hi < g.c + g.a && g.hi - g.lo > 1e-9 * g.a
    }

    /// Solve the linear problem at fixed geometry (pressure, charge and stick traction, coupled
    /// through κq, w13 w and the slip traction, by fixed-point iteration from `guess`) and
    /// return the four residuals (pressure consistency and resultant, stick consistency and
    /// force, each made dimensionless), the state, and whether the inner iteration reached
    /// [`INNER_TOLERANCE`] (it stops at `inner_tolerance`, see [`inner_tolerance`]; an uncoupled
    /// problem is solved exactly in one pass).
    fn evaluate(
        &self,
        g: &Geometry,
        guess: &ContactState,
        inner_tolerance: f64,
    ) -> Result<([f64; 4], ContactState, bool), SolveFailure> {
        let inherited = self
            .base
            .and_then(|b| b.inheritance_for(g.lo, g.hi, self.disc.nodes()))
            .map(|link| {
                let last = self.last_link.borrow();
                match (Arc::try_unwrap(link), last.as_deref()) {
                    (Ok(link), Some(built)) => Arc::new(link.reusing_table_of(built)),
                    (Ok(link), None) => Arc::new(link),
                    (Err(shared), _) => shared,
                }
            });
        let evaluated = self.evaluate_with(g, guess, inherited.clone(), inner_tolerance);
        if inherited.is_some() {
            *self.last_link.borrow_mut() = inherited;
        }
        evaluated
    }

    /// As [`Self::evaluate`], with the inherited correction chosen by the caller (the
    /// finite-difference Jacobian keeps the base point's choice so that it does not straddle
    /// a switch).
    fn evaluate_with(
        &self,
        g: &Geometry,
        guess: &ContactState,
        inherited: Option<Arc<Inherited>>,
        inner_tolerance: f64,
    ) -> Result<([f64; 4], ContactState, bool), SolveFailure> {
        let (model, disc) = (self.model, self.disc);
        let m = disc.nodes();
        let split = guess.split;
        let ystar = model.pressure_compliance(split);
        let kappa = model.pressure_shear_coupling(split);
        let y11 = model.compliance.y11;
        let eta = model.friction;
        let w13 = model.compliance.electric.map_or(0.0, |e| e.w13);
        let local = model.local_pressure_strain(split);
        let potential_control = matches!(
            model.electrode,
            super::Electrode::ConductingPotential { .. }
        );
        let (mid, half) = (0.5 * (g.lo + g.hi), 0.5 * (g.hi - g.lo));
        // Collocation points mapped onto an interval `centre ± half`.
        let mapped = |points: &[f64], centre: f64, half: f64| -> Vec<f64> {
            points.iter().map(|t| centre + half * t).collect()
        };
        let stick_points = mapped(&disc.bounded.collocation, mid, half);
        let pressure_points = mapped(&disc.bounded.collocation, g.c, g.a);
        let charge_points = mapped(&disc.unbounded.collocation, g.c, g.a);
        let electric = split
            .conducting
            .then_some(model.compliance.electric)
            .flatten();
        let w13_over_y33 = electric.map_or(0.0, |e| e.w13 / e.y33);
        let coupled = model.stick_end_kinks && (kappa.abs() > 0.0 || w13_over_y33.abs() > 0.0);
        // The remembered stick ends inside the zone and the parts of q̃ that carry their kinks
        // beyond them (module docs, "Kinks at the stick ends").
        let interior = match (&inherited, coupled) {
            (Some(z), true) => z.interior_roots(g.lo, g.hi),
            _ => Vec::new(),
        };
        let new_zone = StickZone {
            end_signs: [self.signs.0, self.signs.1],
            ..StickZone::new(g.lo, g.hi, BoundedSeries::default(), 0.0)
        };
        let negligible = 1e-14 * eta * guess.pressure_at(guess.centre).abs();
        let extras: Vec<(f64, f64, f64)> = interior
            .iter()
            .filter_map(|r| {
                let (u, v) = kink_domain(r.at, r.side, g.c, g.a);
                let root = pressure_root(r.side, kappa / ystar, eta, r.sign, r.root)
                    * resolved(v - u, g.a, m);
                let (u, v) = if r.side > 0.0 {
                    (r.at, g.hi)
                } else {
                    (g.lo, r.at)
                };
                let change = r.carried_sign - new_zone.end_sign_shape(r.at);
                let amplitude = change * eta * root / (v - u).sqrt();
                // An extra below 1e−14 of η p0 is round-off (a sign change of 1e−17 at a
                // point of a mixed state's blend); kept, it would stop the chain collapsing.
                (amplitude.abs() * 0.5 * (v - u) > negligible).then_some((u, v, amplitude))
            })
            .collect();
        // The part of q̃ fixed by the geometry: the inherited chain and the extras.
        let closed = StickZone {
            inherited: inherited.clone(),
            extras,
            ..new_zone
        };
        // Parts of the stick right-hand side that do not change in the inner iteration (with
        // no charge unknown, whatever charge the state carries is among them).
        let stick_parts = Reused::get_or_make(
            &mut self.reused.borrow_mut().stick,
            PartsKey::new(m, (mid, half), &closed, [0.0; 2]),
            || {
                let (mut chain, mut remembered) = (Vec::with_capacity(m), Vec::with_capacity(m));
                closed.correction_cauchys_into(&stick_points, &mut chain);
                self.memory
                    .strains_into(model, &stick_points, &mut remembered);
                (chain, remembered)
            },
        );
        let (chain_cauchy, remembered) = (&stick_parts.0, &stick_parts.1);
        let fixed: Vec<f64> = stick_points
            .iter()
            .zip(chain_cauchy)
            .zip(remembered)
            .map(|((&x, h), strain)| {
                let fixed_charge = if split.conducting {
                    0.0
                } else {
                    w13 * guess.potential_charge_at(x) / y11
                };
                strain / y11 - h + fixed_charge
            })
            .collect();
        let inherited_force = closed.correction_integral();
        let mut state = guess.clone();
        state.shape_table = None;
        state.half_width = g.a;
        state.centre = g.c;
        state.tangential_load = self.tangential_load;
        state.traction.friction = eta;
        state.traction.left_sign = self.signs.0;
        state.traction.right_sign = self.signs.1;
        state.traction.stick = Some(closed.clone());
        let mixed = (self.signs.0 - self.signs.1).abs() > 0.0;
        // The traction at the pressure and charge points is `η p S + q̃_own + q̃_inherited`;
        // S and the inherited part depend on the geometry only, so they are evaluated once.
        let sampled = |points: &[f64]| -> Vec<(f64, f64)> {
            let mut inherited = Vec::with_capacity(points.len());
            closed.corrections_into(points, &mut inherited);
            points
                .iter()
                .zip(inherited)
                .map(|(&x, inh)| (state.slip_shape(x), inh))
                .collect()
        };
        let ends = if mixed { [g.lo, g.hi] } else { [0.0; 2] };
        let sample_parts = Reused::get_or_make(
            &mut self.reused.borrow_mut().samples,
            PartsKey::new(m, (g.c, g.a), &closed, ends),
            || {
                let charge = if split.conducting {
                    sampled(&charge_points)
                } else {
                    Vec::new()
                };
                (sampled(&pressure_points), charge)
            },
        );
        let (fixed_p, fixed_c) = (&sample_parts.0, &sample_parts.1);
        let (np, nc) = (pressure_points.len(), fixed_c.len());
        let sample_points: Vec<f64> = pressure_points
            .iter()
            .chain(&charge_points[..nc])
            .copied()
            .collect();
        let mut maps = self.scratch.take();
        maps.rebuild(
            &state,
            &stick_points,
            &sample_points,
            m,
            Coefficients {
                local_over_y11: local / y11,
                shape: (!mixed).then_some(eta * self.signs.0),
                charge: split.conducting.then_some(w13 / y11),
            },
        );
        // The kinks of p and w: at the new stick ends, whose q̃ roots are unknowns of the inner
        // iteration, estimated from q̃ at `END_PROBE` and twice that of the half-width inside
        // each end (nearer where a remembered end is close, see `EndProbes`), and at the
        // remembered stick ends inside the zone, whose roots the chain carries.
        let interior_points: Vec<f64> = interior.iter().map(|r| r.at).collect();
        let probes = EndProbes::new(g, m, &closed, &interior_points);
        let kinks = if coupled {
            let mut points = vec![
                (g.lo, -1.0, 0.0, self.signs.0),
                (g.hi, 1.0, 0.0, self.signs.1),
            ];
            points.extend(interior.iter().map(|r| (r.at, r.side, r.root, r.sign)));
            KinkMaps::new(
                &state,
                &points,
                KinkPoints {
                    pressure: &pressure_points,
                    charge: &charge_points[..nc],
                    stick: &stick_points,
                    samples: &sample_points,
                    nodes: &maps.node_points,
                },
                m,
                [kappa / ystar, w13_over_y33, eta],
            )
        } else {
            KinkMaps::default()
        };
        // The inner unknown: q at the pressure points, then at the charge points, then (when
        // coupled) q̃'s root coefficients at the new ends, times √h (Pa).
        // The starting traction. When the guess's own series sits on the same inherited zone
        // (the previous iterate, or the previous step of the phase), its coefficients at this
        // geometry's points with this evaluation's chain and S: two products per point instead
        // of a walk of the guess's chain. Otherwise the guess's traction itself.
        let guess_zone = guess.traction.stick.as_ref();
        let same_chain = guess_zone.is_some_and(|z| {
            z.correction.beta.len() == m
                && guess.pressure.beta.len() == m
                && match (&z.inherited, &closed.inherited) {
                    (Some(u), Some(v)) => Arc::ptr_eq(&u.zone, &v.zone),
                    (None, None) => true,
                    _ => false,
                }
        });
        let (mut p_samples, mut own_samples) = (vec![0.0; np + nc], vec![0.0; np + nc]);
        let mut own_inside = vec![0.0; maps.own_rows.len()];
        let mut x: Vec<f64> = if same_chain {
            let own = &guess_zone.expect("same chain").correction.beta;
            disc.bounded_at_collocation(&guess.pressure.beta, &mut p_samples);
            maps.own_at_samples_into(own, &mut own_inside, &mut own_samples);
            fixed_p
                .iter()
                .chain(fixed_c)
                .zip(&sample_points)
                .enumerate()
                .map(|(k, ((shape, inh), &xs))| {
                    let p = p_samples[k] + guess.kinks_at(&guess.pressure_kinks, xs);
                    eta * p * shape + own_samples[k] + inh
                })
                .collect()
        } else {
            let mut x = Vec::with_capacity(sample_points.len() + 2);
            guess.tractions_into(&sample_points, &mut x);
            x
        };
        // The root unknowns: on the same chain (the previous iterate, or the previous step of the
        // phase) the guess's own roots, which its inner iteration converged; otherwise q̃ of the
        // guess probed at this geometry's probe points. (Probed on the same chain, they were off
        // by the ends' move over the probe distance, 1e−2 of the half-width: the first pass
        // changed them ten times more than the traction, so the stored roots save inner
        // passes.)
        if coupled {
            x.extend(guess_zone.map_or([0.0; 2], |z| {
                if same_chain {
                    [
                        z.end_roots[0] * probes.scale[0],
                        z.end_roots[1] * probes.scale[1],
                    ]
                } else {
                    probes.scaled_roots(|x| z.correction_at(x))
                }
            }));
        }
        let mut fx = vec![0.0; x.len()];
        let mut rhs = vec![0.0; m + 1];
        let mut beta_p = vec![0.0; m];
        let mut beta_q = vec![0.0; m];
        let mut gamma = vec![0.0; m];
        let mut srhs = vec![0.0; m + 1];
        let mut crhs = vec![0.0; m.saturating_sub(1)];
        let mut work = vec![0.0; m + 1];
        let mut stick_sums = StickSums::new(m);
        let mut p_nodes = vec![0.0; maps.shape_nodes.rows()];
        // The kink terms' roots and amplitudes of p and w, refilled in each pass.
        let (mut roots, mut amp, mut w_amp) = (Vec::new(), Vec::new(), Vec::new());
        let scale = model.pressure_scale(split);
        let p_scale = g.a * scale;
        let (mut lambda_p, mut lambda_q) = (0.0, 0.0);
        let mut full = false;
        let mut accel = Anderson::new(5);
        for _ in 0..100 {
            // Pressure for the current shear traction (seed eqs. 52, 54, 56), less the Cauchy
            // transform of its kinks.
            let ends = if coupled {
                [
                    x[np + nc] / probes.scale[0],
                    x[np + nc + 1] / probes.scale[1],
                ]
            } else {
                [0.0; 2]
            };
            kinks.roots_into(ends, &mut roots);
            kinks.pressure_amplitudes_into(&roots, &mut amp);
            w_amp.clear();
            w_amp.resize(amp.len(), 0.0);
            for ((r, &xp), q) in rhs.iter_mut().zip(&pressure_points).zip(&x[..np]) {
                *r = -xp * scale - kappa / ystar * q;
            }
            kinks.cauchy_at_pressure.add_apply(&amp, -1.0, &mut rhs);
            lambda_p = disc.bounded.solve_coefficients(&rhs, &mut beta_p);
            state.pressure.beta.clone_from(&beta_p);
            kinks.kinks_into(&amp, &mut state.pressure_kinks);
            // Charge (seed eqs. 53, 55, 41–42) for the current shear traction. The arcsine
            // moment of q fixes Γ under potential control; under charge control it only gives
            // φ0 and is evaluated once for the accepted state.
            if split.conducting {
                let e = model
                    .compliance
                    .electric
                    .expect("conducting punch on a piezoelectric half-plane");
                let j_q = if potential_control {
                    arcsine_moment(&state)
                } else {
                    0.0
                };
                let (charge, potential) = electric_resultants(model, g.a, self.normal_load, j_q);
                state.charge = charge;
                state.potential = potential;
                let free = charge - model.pressure_charge(self.normal_load);
                kinks.charge_amplitudes_into(&roots, &mut w_amp);
                kinks.kinks_into(&w_amp, &mut state.charge_kinks);
                for (r, q) in crhs.iter_mut().zip(&x[np..np + nc]) {
                    *r = -e.w13 / e.y33 * q;
                }
                kinks.cauchy_at_charge.add_apply(&w_amp, -1.0, &mut crhs);
                let kinks_force =
                    state.potential_charge_force() - g.a * state.potential_charge.integral();
                disc.unbounded
                    .solve_coefficients(&crhs, (free - kinks_force) / g.a, &mut gamma);
                state.potential_charge.gamma.clone_from(&gamma);
            }
            // Stick traction (seed eqs. 50–51/58–59, 60, 63); `H'(pS)` is `s H'p` when both slip
            // zones have the same sign s.
            maps.stick_terms(&beta_p, &gamma, &mut stick_sums, &mut srhs, &mut work);
            if let Some(eta_s) = maps.coefficients.shape {
                kinks.cauchy_at_stick.add_apply(&amp, -eta_s, &mut srhs);
            }
            // The remembered kinks' terms reach into the stick zone: their local parts.
            kinks.at_stick.add_apply(&amp, local / y11, &mut srhs);
            kinks.at_stick.add_apply(&w_amp, w13 / y11, &mut srhs);
            if mixed {
                maps.shape_nodes.apply(&beta_p, &mut p_nodes);
                kinks.cauchy_at_stick.add_apply(&amp, 1.0, &mut work);
                kinks.at_nodes.add_apply(&amp, 1.0, &mut p_nodes);
                for (i, r) in srhs.iter_mut().enumerate() {
                    let shape =
                        maps.stick_shape[i] * work[i] + dot(maps.shape_weights.row(i), &p_nodes);
                    *r -= eta * shape;
                }
            }
            for (r, f) in srhs.iter_mut().zip(&fixed) {
                *r += f;
            }
            lambda_q = disc.bounded.solve_coefficients(&srhs, &mut beta_q);
            // p at the sample points (sine transforms) and q̃'s own part there (its map).
            disc.bounded_at_collocation(&beta_p, &mut p_samples);
            kinks.at_samples.add_apply(&amp, 1.0, &mut p_samples);
            maps.own_at_samples_into(&beta_q, &mut own_inside, &mut own_samples);
            for (k, (shape, inh)) in fixed_p.iter().chain(fixed_c).enumerate() {
                fx[k] = eta * p_samples[k] * shape + own_samples[k] + inh;
            }
            if coupled {
                let [left, right] = probes.scaled_roots_of(&beta_q);
                fx[np + nc] = left;
                fx[np + nc + 1] = right;
            }
            if let Some(stick) = state.traction.stick.as_mut() {
                stick.correction.beta.clone_from(&beta_q);
                stick.end_roots = ends;
            }
            let p0 = state.pressure_at(g.c).abs().max(1e-300);
            let change = fx
                .iter()
                .zip(&x)
                .map(|(n, o)| (n - o).abs())
                .fold(0.0, f64::max)
                / (eta * p0);
            let exact = kappa == 0.0 && !split.conducting;
            if exact || change < inner_tolerance {
                full = exact || change < INNER_TOLERANCE;
                break;
            }
            accel.next(&mut x, &fx);
        }
        self.scratch.replace(maps);
        state.shape_table = None;
        let p0 = state.pressure_at(g.c).abs().max(1e-300);
        let pressure_force = state.pressure_force();
        let stick = state.traction.stick.as_ref().expect("set above");
        let shape_force = if (self.signs.0 - self.signs.1).abs() > 0.0 {
            // ∫ p S dx over the contact, piecewise by the graded rule.
            state.contact_integral(None, &|xs, out| {
                state.pressures_into(xs, out);
                for (p, &x) in out.iter_mut().zip(xs) {
                    *p *= state.slip_shape(x);
                }
            })
        } else {
            self.signs.1 * pressure_force
        };
        let q_force = half * stick.correction.integral() + inherited_force + eta * shape_force;
        let residual = [
            lambda_p / p_scale,
            (pressure_force - self.normal_load) / self.normal_load,
            lambda_q / (eta * p0),
            (q_force - self.tangential_load) / (eta * self.normal_load),
        ];
        Ok((residual, state, full))
    }
}

/// Tolerance of the inner iteration: the largest change of the traction in a pass, relative
/// to `η p0`.
const INNER_TOLERANCE: f64 = 1e-14;

/// Largest first residual with which a recalled step is continued ([`Recalled`]): where the
/// step's problem is the recalled one's, the first residual is the recalled state's own, below
/// the solver's tolerance but for round-off (measured over the 22 runs of
/// the regression runs at the tolerance 1e−11: median 1.1e−12, largest 1.14e−11), while a
/// problem that differs starts
/// at the size of a load step's change of the residuals (1e−4–1e−3). A larger one means the
/// problem differs, and the step's own attempts decide among its sign patterns.
const RECALL_RESIDUAL: f64 = 1e-9;

/// The inner tolerance of a trial iterate when the current residual norm is `residual`: an
/// inexact Newton method, whose residuals need only be accurate to a small fraction (here
/// 1e−3) of the residual being reduced; never looser than 1e−8 nor tighter than
/// [`INNER_TOLERANCE`]. A step is accepted only on a residual evaluated at the full tolerance,
/// so the loose trials save inner passes without changing the accepted states. The first step
/// after a reversal, whose failed attempts wander, reacts to the inner tolerance erratically.
fn inner_tolerance(residual: f64) -> f64 {
    (1e-3 * residual).clamp(INNER_TOLERANCE, LOOSEST_INNER_TOLERANCE)
}

/// The loosest inner tolerance of a trial iterate ([`inner_tolerance`]).
const LOOSEST_INNER_TOLERANCE: f64 = 1e-8;

/// The inner tolerance of the finite-difference Jacobian's evaluations: its differences over
/// steps of 1e−6 a change the residuals by about 1e−6, so 1e−11 leaves 1e−5 of the Jacobian,
/// and a tighter tolerance would cost inner passes without changing the states.
const JACOBIAN_INNER_TOLERANCE: f64 = 1e-11;

/// The coefficients that scale the rows of [`InnerMaps`].
#[derive(Debug, Clone, Copy, Default)]
struct Coefficients {
    /// `(w12 + χ w13)/y11`: the pressure's local term in the stick equation.
    local_over_y11: f64,
    /// `η s` when both slip zones have the sign s (the `−η s H'p` term folded into the
    /// pressure rows); `None` for mixed signs, whose `H'(pS)` is assembled separately.
    shape: Option<f64>,
    /// `w13/y11` when the charge is an unknown (conducting punch).
    charge: Option<f64>,
}

/// p's square-root coefficient on the slip side of a kink point, `side (κ/Y*) k/(1 + α²)`,
/// `α = κηS/Y*`, for q̃'s root k there and the slip sign S (module docs).
fn pressure_root(side: f64, kappa: f64, eta: f64, sign: f64, k: f64) -> f64 {
    let alpha = kappa * eta * sign;
    side * kappa * k / (1.0 + alpha * alpha)
}

/// How far a kink term on a stretch of `length` is kept (1) or switched off (0): a stretch
/// narrower than the grid spacing at the contact ends, `a (π/M)²`, holds no collocation point;
/// smootherstep between one and two spacings.
fn resolved(length: f64, a: f64, m: usize) -> f64 {
    let spacing = a * (std::f64::consts::PI / m as f64).powi(2);
    smootherstep(length / spacing - 1.0)
}

/// Where the kink functions are needed in an evaluation.
struct KinkPoints<'a> {
    pressure: &'a [f64],
    charge: &'a [f64],
    stick: &'a [f64],
    samples: &'a [f64],
    /// The shape quadrature's nodes (mixed slip signs only: `H'(pS)` needs p there).
    nodes: &'a [f64],
}

/// The kink terms of one evaluation (tangential module docs, "Kinks at the stick ends"): their
/// points, the local relations that give their amplitudes from q̃'s root coefficients, and the
/// kink functions (half-ellipses over a) and their Cauchy transforms at the points where the
/// inner iteration needs them, as matrices over the terms.
#[derive(Default)]
struct KinkMaps {
    /// `(point, side)` of each term; the first two are the new stick ends.
    points: Vec<(f64, f64)>,
    /// The roots k of the remembered terms (from the third on).
    fixed_roots: Vec<f64>,
    /// Per term: `side (κ/Y*)/(1 + α²)`, `α = κηS/Y*` with S the slip sign beside the point
    /// when its root formed ([`pressure_root`]).
    pressure_factor: Vec<f64>,
    /// Per term: `(κ/Y*) η² S²`, the factor of p's stick-side root in w's relation.
    stick_side: Vec<f64>,
    /// Per term: the factor from a root coefficient to the amplitude of the half-ellipse
    /// over a, `a/√L` (L the term's stretch), switched off for stretches the grid does not
    /// resolve.
    to_amplitude: Vec<f64>,
    /// w13/y33.
    charge: f64,
    cauchy_at_pressure: RowMatrix,
    cauchy_at_charge: RowMatrix,
    cauchy_at_stick: RowMatrix,
    at_stick: RowMatrix,
    at_samples: RowMatrix,
    at_nodes: RowMatrix,
}

impl KinkMaps {
    /// The maps for the terms `points` (`(point, side, root, sign)`, the root used only for the
    /// remembered ones) on `state`'s geometry; `coefficients` are κ/Y*, w13/y33 and η.
    ///
    /// A term on a stretch the grid does not resolve is switched off ([`resolved`]):
    /// unresolved, it only disturbed the search for the first state after a reversal, whose
    /// edge slip zones start that thin (insulating Figure-3 history: a left slip zone of
    /// 8e−5 a).
    fn new(
        state: &ContactState,
        points: &[(f64, f64, f64, f64)],
        at: KinkPoints<'_>,
        m: usize,
        coefficients: [f64; 3],
    ) -> Self {
        let [kappa, charge, eta] = coefficients;
        let (c, a) = (state.centre, state.half_width);
        let domains: Vec<(f64, f64)> = points
            .iter()
            .map(|&(x0, side, _, _)| kink_domain(x0, side, c, a))
            .collect();
        let pressure_factor = points
            .iter()
            .map(|&(_, side, _, sign)| pressure_root(side, kappa, eta, sign, 1.0))
            .collect();
        let stick_side = points
            .iter()
            .map(|&(_, _, _, sign)| kappa * eta * eta * sign * sign)
            .collect();
        let to_amplitude = domains
            .iter()
            .map(|&(u, v)| {
                let blend = resolved(v - u, a, m);
                if blend > 0.0 {
                    blend * a / (v - u).sqrt()
                } else {
                    0.0
                }
            })
            .collect();
        let table = |xs: &[f64], f: &dyn Fn(f64, f64, f64) -> f64| {
            let mut out = RowMatrix::zeros(xs.len(), points.len());
            for (i, &x) in xs.iter().enumerate() {
                for (o, &(u, v)) in out.row_mut(i).iter_mut().zip(&domains) {
                    *o = f(x, u, v) / a;
                }
            }
            out
        };
        Self {
            points: points.iter().map(|&(x0, side, _, _)| (x0, side)).collect(),
            fixed_roots: points.iter().skip(2).map(|&(_, _, k, _)| k).collect(),
            pressure_factor,
            stick_side,
            to_amplitude,
            charge,
            cauchy_at_pressure: table(at.pressure, &half_ellipse_cauchy),
            cauchy_at_charge: table(at.charge, &half_ellipse_cauchy),
            cauchy_at_stick: table(at.stick, &half_ellipse_cauchy),
            at_stick: table(at.stick, &half_ellipse),
            at_samples: table(at.samples, &half_ellipse),
            at_nodes: table(at.nodes, &half_ellipse),
        }
    }

    /// The root coefficients of all terms for the new stick ends' `ends`, into `out`.
    fn roots_into(&self, ends: [f64; 2], out: &mut Vec<f64>) {
        out.clear();
        if !self.points.is_empty() {
            out.extend(ends.iter().chain(&self.fixed_roots));
        }
    }

    /// The amplitudes of p's kinks, into `out`: p's root on the slip side of each point is
    /// `A = side (κ/Y*) k/(1 + α²)`.
    fn pressure_amplitudes_into(&self, roots: &[f64], out: &mut Vec<f64>) {
        out.clear();
        out.extend(
            roots
                .iter()
                .zip(&self.pressure_factor)
                .zip(&self.to_amplitude)
                .map(|((k, f), t)| f * k * t),
        );
    }

    /// The amplitudes of w's kinks, into `out`: `B = side (w13/y33)(k − side (κ/Y*) η² S² A)`
    /// with p's root A (q = ηSp + q̃ carries p's stick-side root −side α A next to q̃'s).
    fn charge_amplitudes_into(&self, roots: &[f64], out: &mut Vec<f64>) {
        out.clear();
        out.extend(roots.iter().enumerate().map(|(j, k)| {
            let side = self.points[j].1;
            let root_p = self.pressure_factor[j] * k;
            side * self.charge * (k - side * self.stick_side[j] * root_p) * self.to_amplitude[j]
        }));
    }

    /// The kink terms with amplitudes `amp`, into `out` (its allocation kept).
    fn kinks_into(&self, amp: &[f64], out: &mut Kinks) {
        out.0.clear();
        out.0.extend(
            self.points
                .iter()
                .zip(amp)
                .filter(|(_, a)| a.abs() > 0.0)
                .map(|(&(at, side), &amplitude)| Kink {
                    at,
                    side,
                    amplitude,
                }),
        );
    }
}

/// Where q̃'s square-root coefficients at the stick ends are read: at `END_PROBE` and twice
/// that of the zone's half-width h inside each end.
const END_PROBE: f64 = 0.01;

/// The square-root coefficients of q̃ (own series and inherited correction) at the stick
/// ends, `q̃ ≈ k_lo √(x − lo)` and `q̃ ≈ k_hi √(hi − x)`, by Richardson's extrapolation of
/// `q̃/√r` from the distances `r = d` and `2d` (`d = END_PROBE h`): `k ≈ 2 q̃(d)/√d − q̃(2d)/√(2d)`,
/// exact for `k√r (1 + c r)`. Where a remembered stick end inside the zone (whose root q̃
/// carries, [`super::RememberedRoot`]) lies closer to an end than `4d`, d there is a quarter
/// of its distance, so that both probes read the stretch between the two roots (unless that
/// puts them closer to the end than the series' first node: then d stays): in a steady
/// cycle the extreme states' stick ends lie about 0.01a apart, and probes straddling the
/// remembered one misread k, whose kinks the series then had to carry (`docs/performance.md`,
/// "Convergence in M"). Reading k from the series' end values `ψ(±1)`
/// instead (the exact limit of a polynomial) is ill-conditioned: the sum
/// `Σ (±1)ⁿ (n + 1) β_n` weighs the coefficients' tail, and at M = 256 it moved by 1e−3 of
/// itself between evaluations 1e−6 a apart, which stalled steps at residuals of 1e−7. The
/// coefficients are carried scaled by `scale = √d` of their end (Pa,
/// `k √d = 2 q̃(d) − q̃(2d)/√2`: the root's part of q̃ at the probes), so that the inner
/// iteration converges them as far as the traction; scaled by √h, their round-off, amplified
/// by `√(h/d)`, kept the inner iteration of a recalled step at M = 512 at its tolerance for
/// ten passes instead of four once the probes moved nearer.
struct EndProbes {
    /// Density rows of the own series at `lo + d_lo`, `lo + 2d_lo`, `hi − d_hi`, `hi − 2d_hi`.
    rows: [Vec<f64>; 4],
    /// The closed-form part of q̃ (inherited chain and extras) at the same points.
    closed: [f64; 4],
    /// The same points (m).
    points: [f64; 4],
    /// √d at each end: a root's effect on q̃ at the probes, so that the inner iteration
    /// converges the roots as far as it does the traction.
    scale: [f64; 2],
}

impl EndProbes {
    fn new(g: &Geometry, m: usize, closed: &StickZone, interior: &[f64]) -> Self {
        let half = 0.5 * (g.hi - g.lo);
        let near = |end: f64| {
            interior
                .iter()
                .map(|x| (x - end).abs())
                .fold(f64::INFINITY, f64::min)
        };
        // A probe closer to the end than the series' first node, `h (1 − cos(π/(M + 1)))`,
        // reads what the series cannot resolve; there the standard probes are kept.
        let standard = END_PROBE * half;
        let floor = half * (1.0 - (std::f64::consts::PI / (m + 1) as f64).cos());
        let d = [g.lo, g.hi].map(|end| {
            let clear = 0.25 * near(end);
            if clear < standard && clear >= floor {
                clear
            } else {
                standard
            }
        });
        let points = [
            g.lo + d[0],
            g.lo + 2.0 * d[0],
            g.hi - d[1],
            g.hi - 2.0 * d[1],
        ];
        let rows = points.map(|x| {
            let mut row = vec![0.0; m];
            BoundedSeries::density_row((x - 0.5 * (g.lo + g.hi)) / half, &mut row);
            row
        });
        Self {
            rows,
            closed: points.map(|x| closed.correction_at(x)),
            points,
            scale: d.map(f64::sqrt),
        }
    }

    /// `[k_lo, k_hi]` times `scale` from q̃ at the four points.
    fn extrapolate(&self, v: [f64; 4]) -> [f64; 2] {
        // k √d = 2 q̃(d) − q̃(2d)/√2.
        let root = |near: f64, far: f64| 2.0 * near - far * std::f64::consts::FRAC_1_SQRT_2;
        [root(v[0], v[1]), root(v[2], v[3])]
    }

    /// The scaled coefficients of the q̃ whose own series is `beta`.
    fn scaled_roots_of(&self, beta: &[f64]) -> [f64; 2] {
        let mut v = self.closed;
        for (vi, row) in v.iter_mut().zip(&self.rows) {
            *vi += dot(row, beta);
        }
        self.extrapolate(v)
    }

    /// The scaled coefficients of a q̃ given as a function.
    fn scaled_roots(&self, f: impl Fn(f64) -> f64) -> [f64; 2] {
        self.extrapolate(self.points.map(f))
    }
}
/// The buffers of [`InnerMaps::stick_terms`] for series of M terms at M + 1 stick points.
struct StickSums {
    coefficients: [Vec<f64>; 2],
    sums: [Vec<f64>; 2],
}

impl StickSums {
    fn new(m: usize) -> Self {
        Self {
            coefficients: [vec![0.0; m + 2], vec![0.0; m + 2]],
            sums: [vec![0.0; m + 1], vec![0.0; m + 1]],
        }
    }
}

/// The linear maps of the inner iteration at one geometry, as matrices on the series
/// coefficients (each applied once per pass instead of a Clenshaw sum per point): at the stick
/// points, the stick right-hand side from the pressure (`local p − η s y11 H'p`, over y11) and
/// from the charge (`w13 w`, over y11), both from one matrix of `T_n` values
/// ([`Self::stick_terms`]; one matrix instead of one each for p, w and `H'p`: less memory
/// to read at every pass); at the pressure and charge points inside the stick
/// zone, the density of the stick correction (zero at the others). (The pressure's density at
/// its own and the charge's collocation points does not depend on the geometry: it is a
/// sine transform, [`Discretisation::bounded_at_collocation`].) For mixed slip signs,
/// `H'(pS)(x) = S(x) H'p(x) + (1/π)∫ p(t)(S(t) − S(x))/(t − x) dt` at the stick points (as
/// `ContactState::shape_cauchy`) is kept in three parts: `H'p` at the stick points, p at the
/// graded nodes of the slip and stick pieces, and the quotient weights.
#[derive(Default)]
struct InnerMaps {
    /// `T_n(τ_i)`, n = 0 … M + 1, at the stick points (τ in the contact's coordinate).
    stick_t: ColumnMatrix,
    /// `1/√(1 − τ_i²)` at the stick points.
    stick_root: Vec<f64>,
    coefficients: Coefficients,
    /// Rows at the sample points inside the stick zone only (`own_rows`): q̃'s own part is
    /// zero outside.
    own_at_samples: ColumnMatrix,
    /// The indices of the sample points inside the stick zone, increasing.
    own_rows: Vec<usize>,
    shape_nodes: ColumnMatrix,
    shape_weights: RowMatrix,
    /// S at the stick points.
    stick_shape: Vec<f64>,
    /// The positions of the shape quadrature's nodes (mixed slip signs only).
    node_points: Vec<f64>,
}

impl InnerMaps {
    /// The maps for `state`'s geometry (contact and stick zone) at the stick collocation
    /// points and at the pressure-then-charge sample points, for series of M coefficients.
    fn rebuild(
        &mut self,
        state: &ContactState,
        stick_points: &[f64],
        sample_points: &[f64],
        m: usize,
        k: Coefficients,
    ) {
        let (c, a) = (state.centre, state.half_width);
        let stick = state.traction.stick.as_ref().expect("stick zone set");
        let rows = stick_points.len();
        let Self {
            stick_t,
            stick_root,
            own_at_samples,
            own_rows,
            shape_nodes,
            shape_weights,
            ..
        } = self;
        // The stick points lie inside the contact, where `cauchy_row` is the T recurrence.
        let taus: Vec<f64> = stick_points.iter().map(|&xs| (xs - c) / a).collect();
        debug_assert!(taus.iter().all(|t| t.abs() < 1.0));
        stick_t.refill(m + 2, &taus, |t| [t, 1.0, 1.0]);
        stick_root.clear();
        stick_root.extend(taus.iter().map(|t| 1.0 / (1.0 - t * t).sqrt()));
        let stick_shape: Vec<f64> = stick_points.iter().map(|&x| state.slip_shape(x)).collect();
        let (mid, half) = (stick.mid(), stick.half());
        // Rows only where the density is not zero: in the bench's forward step at 0.35 ηP
        // (M = 128) 122 of the 256 sample points lie outside the stick zone (counted).
        own_rows.clear();
        let mut inside_taus = Vec::with_capacity(sample_points.len());
        for (k, &xq) in sample_points.iter().enumerate() {
            let tau = (xq - mid) / half;
            if tau.abs() < 1.0 {
                own_rows.push(k);
                inside_taus.push(tau);
            }
        }
        own_at_samples.refill(m, &inside_taus, BoundedSeries::density_start);
        let mut node_points = Vec::new();
        if k.shape.is_none() {
            let table = state.shape_quadrature(stick);
            node_points = table.iter().map(|&(t, _, _)| t).collect();
            let node_taus: Vec<f64> = table.iter().map(|&(t, _, _)| (t - c) / a).collect();
            shape_nodes.refill(m, &node_taus, BoundedSeries::density_start);
            shape_weights.reset(rows, table.len());
            for (i, (&xs, &sx)) in stick_points.iter().zip(&stick_shape).enumerate() {
                for (wij, &(t, w, st)) in shape_weights.row_mut(i).iter_mut().zip(&table) {
                    if (t - xs).abs() > 1e-14 * a {
                        *wij = w * (st - sx) / (t - xs) / std::f64::consts::PI;
                    }
                }
            }
        } else {
            shape_nodes.clear();
            shape_weights.reset(0, 0);
        }
        self.stick_shape = stick_shape;
        self.coefficients = k;
        self.node_points = node_points;
    }

    /// The stick rows' terms of the pressure (coefficients `beta_p`, β_n for n = 1 … M) and
    /// of the charge (`gamma`, γ_n for n = 0 … M − 1) into `srhs`: `local/y11 · p + η s T·β`
    /// (the `−η s H'p` term, with equal slip signs) `+ w13/y11 · w`; with mixed slip signs the
    /// `η s` term is left out and `H'p` at the stick points goes into `cauchy` instead. With
    /// `√(1−τ²) U_{n−1}(τ) = (T_{n−1}(τ) − T_{n+1}(τ))/(2√(1−τ²))` both densities are T
    /// series over `√(1−τ²)`, so one matrix of `T_n(τ_i)` serves every term, read once for
    /// the two coefficient vectors: `a` (the densities' coefficients, L (β_{k+1} − β_{k−1})/2
    /// + W γ_k) and `b` (η s β_k, or −β_k for `H'p`).
    fn stick_terms(
        &self,
        beta_p: &[f64],
        gamma: &[f64],
        buffers: &mut StickSums,
        srhs: &mut [f64],
        cauchy: &mut [f64],
    ) {
        let Coefficients {
            local_over_y11,
            shape,
            charge,
        } = self.coefficients;
        let m = beta_p.len();
        let beta = |k: usize| {
            if (1..=m).contains(&k) {
                beta_p[k - 1]
            } else {
                0.0
            }
        };
        let [a, b] = &mut buffers.coefficients;
        let factor = shape.unwrap_or(-1.0);
        for (k, (ak, bk)) in a.iter_mut().zip(b.iter_mut()).enumerate() {
            let below = k.checked_sub(1).map_or(0.0, beta);
            *ak = 0.5 * local_over_y11 * (beta(k + 1) - below);
            *bk = factor * beta(k);
        }
        if let Some(w) = charge {
            for (ak, g) in a.iter_mut().zip(gamma) {
                *ak += w * g;
            }
        }
        let [ya, yb] = &mut buffers.sums;
        self.stick_t.apply_pair([a, b], [ya, yb]);
        let densities = srhs.iter_mut().zip(ya.iter().zip(&self.stick_root));
        if shape.is_some() {
            for ((r, (ya, root)), yb) in densities.zip(yb.iter()) {
                *r = root * ya + yb;
            }
        } else {
            for (r, (ya, root)) in densities {
                *r = root * ya;
            }
            cauchy.copy_from_slice(yb);
        }
    }

    /// q̃'s own part with coefficients `beta` at every sample point into `out`: the products
    /// of the rows inside the stick zone (into `inside`, one entry per row), zero elsewhere.
    fn own_at_samples_into(&self, beta: &[f64], inside: &mut [f64], out: &mut [f64]) {
        self.own_at_samples.apply(beta, inside);
        out.fill(0.0);
        for (&k, &v) in self.own_rows.iter().zip(inside.iter()) {
            out[k] = v;
        }
    }
}

thread_local! {
    /// The [`InnerMaps`] of this thread's last step, whose matrices the next step refills
    /// (every evaluation writes all of them). Allocated afresh at every step, they were
    /// mapped and zeroed page by page: about half of a recalled step at M = 512, whose
    /// matrices hold 10 MB.
    static INNER_MAPS: RefCell<InnerMaps> = RefCell::default();
    /// The same for the coarse grid's evaluations ([`coarse_jacobian`]).
    static COARSE_MAPS: RefCell<InnerMaps> = RefCell::default();
}

/// This thread's [`InnerMaps`] of one grid, lent to one step and given back when the step
/// ends.
struct LentMaps(
    RefCell<InnerMaps>,
    &'static std::thread::LocalKey<RefCell<InnerMaps>>,
);

impl LentMaps {
    fn lend() -> Self {
        Self::lend_from(&INNER_MAPS)
    }

    fn lend_from(home: &'static std::thread::LocalKey<RefCell<InnerMaps>>) -> Self {
        Self(RefCell::new(home.take()), home)
    }
}

impl Drop for LentMaps {
    fn drop(&mut self) {
        self.1.set(self.0.take());
    }
}

/// Anderson acceleration (type II) of a fixed-point iteration `x ← F(x)`: the next iterate
/// combines the last `depth` values of F so that the combined residual `F(x) − x` is least
/// squares. For the affine map of the inner iteration it converges in a few steps where the
/// plain iteration contracts only by the coupling factor per step.
struct Anderson {
    depth: usize,
    /// Whether `last_res` and `last_f` hold a previous pass.
    started: bool,
    /// Previous residual `F(x) − x` and `F(x)`.
    last_res: Vec<f64>,
    last_f: Vec<f64>,
    /// Differences of residuals and of F values, newest last; the oldest pair's buffers are
    /// reused for the newest once `depth` are held.
    d_res: VecDeque<Vec<f64>>,
    d_f: VecDeque<Vec<f64>>,
    /// `gram[i][j] = d_res[i] · d_res[j]`, kept from pass to pass: a pass adds the newest
    /// difference's row, not the whole matrix again.
    gram: [[f64; SMALL]; SMALL],
    /// This pass's residual.
    res: Vec<f64>,
}

impl Anderson {
    fn new(depth: usize) -> Self {
        assert!(depth <= SMALL, "Anderson depth at most {SMALL}");
        Self {
            depth,
            started: false,
            last_res: Vec::new(),
            last_f: Vec::new(),
            d_res: VecDeque::with_capacity(depth + 1),
            d_f: VecDeque::with_capacity(depth + 1),
            gram: [[0.0; SMALL]; SMALL],
            res: Vec::new(),
        }
    }

    /// Replace `x` by the next iterate given `fx = F(x)`.
    fn next(&mut self, x: &mut [f64], fx: &[f64]) {
        self.res.clear();
        self.res.extend(fx.iter().zip(x.iter()).map(|(f, v)| f - v));
        if self.started {
            let (mut dr, mut df) = if self.d_res.len() >= self.depth {
                // The oldest difference leaves the Gram matrix too.
                for i in 1..self.depth {
                    for j in 1..self.depth {
                        self.gram[i - 1][j - 1] = self.gram[i][j];
                    }
                }
                (
                    self.d_res.pop_front().unwrap_or_default(),
                    self.d_f.pop_front().unwrap_or_default(),
                )
            } else {
                (Vec::new(), Vec::new())
            };
            dr.clear();
            dr.extend(self.res.iter().zip(&self.last_res).map(|(a, b)| a - b));
            df.clear();
            df.extend(fx.iter().zip(&self.last_f).map(|(a, b)| a - b));
            let newest = self.d_res.len();
            for (i, di) in self.d_res.iter().enumerate() {
                let g = dot(di, &dr);
                (self.gram[i][newest], self.gram[newest][i]) = (g, g);
            }
            self.gram[newest][newest] = dot(&dr, &dr);
            self.d_res.push_back(dr);
            self.d_f.push_back(df);
        }
        self.started = true;
        self.last_res.clone_from(&self.res);
        self.last_f.clear();
        self.last_f.extend_from_slice(fx);
        x.copy_from_slice(fx);
        let k = self.d_res.len();
        if k == 0 {
            return;
        }
        // Normal equations of min |res − ΔR γ| (k ≤ depth), lightly regularised; the dot
        // products in SIMD lanes (as scalar sums, a chain of dependent additions each, they
        // took a third of a pass at M = 128).
        let mut gram = [[0.0; SMALL + 1]; SMALL];
        for ((row, kept), di) in gram.iter_mut().zip(&self.gram).zip(&self.d_res) {
            row[..k].copy_from_slice(&kept[..k]);
            row[k] = dot(di, &self.res);
        }
        let trace: f64 = (0..k).map(|i| gram[i][i]).sum::<f64>().max(1e-300);
        for (i, row) in gram.iter_mut().take(k).enumerate() {
            row[i] += 1e-12 * trace;
        }
        let Some(gamma) = solve_small(gram, k) else {
            return;
        };
        for (i, gi) in gamma[..k].iter().enumerate() {
            for (v, d) in x.iter_mut().zip(&self.d_f[i]) {
                *v -= gi * d;
            }
        }
    }
}

/// Most unknowns of [`solve_small`] (and the deepest Anderson history).
const SMALL: usize = 5;

/// Solve the `n × n` system (`n ≤ SMALL`) in the first n rows `[A | b]` of `rows` (b in column
/// n) by Gaussian elimination with partial pivoting; the solution in the first n entries. On
/// the stack: it runs at every pass of the inner iteration.
#[allow(clippy::needless_range_loop)]
fn solve_small(mut rows: [[f64; SMALL + 1]; SMALL], n: usize) -> Option<[f64; SMALL]> {
    debug_assert!(n <= SMALL);
    for col in 0..n {
        let piv = (col..n).max_by(|&x, &y| rows[x][col].abs().total_cmp(&rows[y][col].abs()))?;
        if rows[piv][col].abs() < 1e-300 {
            return None;
        }
        rows.swap(col, piv);
        for row in col + 1..n {
            let f = rows[row][col] / rows[col][col];
            for k in col..=n {
                rows[row][k] -= f * rows[col][k];
            }
        }
    }
    let mut x = [0.0; SMALL];
    for row in (0..n).rev() {
        let s: f64 = (row + 1..n).map(|k| rows[row][k] * x[k]).sum();
        x[row] = (rows[row][n] - s) / rows[row][row];
    }
    x[..n].iter().all(|v| v.is_finite()).then_some(x)
}

fn norm(r: &[f64; 4]) -> f64 {
    r.iter().map(|v| v * v).sum::<f64>().sqrt()
}

/// Solve the 4×4 linear system `J dx = −r` (see [`solve_small`]).
fn solve4(j: [[f64; 4]; 4], r: [f64; 4]) -> Option<[f64; 4]> {
    let mut rows = [[0.0; SMALL + 1]; SMALL];
    for ((row, ji), ri) in rows.iter_mut().zip(j).zip(r) {
        row[..4].copy_from_slice(&ji);
        row[4] = -ri;
    }
    solve_small(rows, 4).map(|x| [x[0], x[1], x[2], x[3]])
}

/// What a step passes to the next one of the same phase: its slip signs and Jacobian.
#[derive(Debug, Clone, Copy, PartialEq)]
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
#[derive(Debug, Clone, Copy, PartialEq)]
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
#[derive(Debug, Clone)]
pub struct Recalled {
    /// The earlier step's state.
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

/// Solve one step at tangential load `tangential_load` with slip sign `sign`, starting from
/// `start` (the previous step), stick-zone guesses tried in turn and the phase's inherited
/// correction chain `base`. `contact`, when given, is the predicted contact half-width and
/// centre `(a, c)` from which the attempts with the first stick-zone guess start (otherwise
/// they start from `start`'s). `recalled`, when given, is tried first (see [`Recalled`]);
/// `last_start`, at a phase start, is how the last phase that began mixed began: its pattern
/// is then tried after the standard one's attempts and before the other mixed ones, from its
/// remembered edge ([`PhaseStart`], [`SlipOptions::mixed_start_guesses`]).
#[allow(clippy::too_many_arguments)]
pub fn solve_slip(
    model: &ContactModel,
    disc: &Discretisation,
    memory: &Memory,
    base: Option<&Arc<StickZone>>,
    start: &ContactState,
    tangential_load: f64,
    sign: f64,
    guesses_in: &[(f64, f64)],
    contact: Option<(f64, f64)>,
    warm: Option<&WarmStart>,
    recalled: Option<&Recalled>,
    last_start: Option<&PhaseStart>,
    options: SlipOptions,
) -> Result<SlipStep, SolveFailure> {
    let guess = guesses_in[0];
    // Both slip zones normally follow the load (seed Section 4); right after a reversal in a
    // coupled contact one edge may keep its previous direction while the contact shifts, so
    // the mixed states are tried when the standard one has no solution.
    //
    // The stick ends can also jump: when the load passes an earlier turning point (Masing
    // memory), the part of the zone that is already at the friction limit slips at once and
    // the ends move to an older stick/slip boundary of the memory. So the remembered
    // boundaries inside the current zone are tried as starting points when the warm start fails.
    let (c, a) = (start.centre, start.half_width);
    let inset = 1e-3 * a;
    let breaks: Vec<f64> = memory
        .breakpoints()
        .into_iter()
        .filter(|&x| x > guess.0.min(c - a) - a && x < guess.1.max(c + a) + a)
        .collect();
    let mut remembered = Vec::new();
    for i in 0..breaks.len() / 2 {
        let (l, r) = (breaks[i], breaks[breaks.len() - 1 - i]);
        if r - l > 2.0 * inset && l > c - a && r < c + a {
            remembered.push((l + inset, r - inset));
        }
    }
    // Other pairs of remembered boundaries (an earlier turning point's zone need not be
    // nested symmetrically in the breakpoint list), widest first.
    let mut pairs: Vec<(f64, f64)> = Vec::new();
    for (i, &l) in breaks.iter().enumerate() {
        for &r in &breaks[i + 1..] {
            if r - l > 2.0 * inset && l > c - a && r < c + a {
                pairs.push((l + inset, r - inset));
            }
        }
    }
    pairs.sort_by(|x, y| (y.1 - y.0).total_cmp(&(x.1 - x.0)));
    remembered.extend(pairs);
    let mut warm_guesses: Vec<(f64, f64)> = Vec::new();
    let mut jump_guesses: Vec<(f64, f64)> = Vec::new();
    for (k, g) in guesses_in.iter().chain(&remembered).enumerate() {
        let same = |h: &(f64, f64)| (h.0 - g.0).abs().max((h.1 - g.1).abs()) <= 1e-12 * a;
        if !warm_guesses.iter().chain(&jump_guesses).any(same) {
            if k < guesses_in.len() {
                warm_guesses.push(*g);
            } else {
                jump_guesses.push(*g);
            }
        }
    }
    // Mixed states: inward friction at both edges (q > 0 on the left, q < 0 on the right)
    // before outward; both patterns are their own mirror images, so the order does not
    // depend on the direction of loading. At the first step of a phase (no warm start) the
    // mixed states are what the reversal needs, and the continuations are tried in every
    // state before the jumps to remembered boundaries; later in a phase the jumps of the
    // standard state come first.
    let patterns = [(sign, sign), (1.0, -1.0), (-1.0, 1.0)];
    let mut plan = Vec::new();
    if warm.is_none() {
        for set in [&warm_guesses, &jump_guesses] {
            for signs in patterns {
                plan.extend(set.iter().map(|&g| (signs, g)));
            }
        }
    } else {
        for signs in patterns {
            for set in [&warm_guesses, &jump_guesses] {
                plan.extend(set.iter().map(|&g| (signs, g)));
            }
        }
    }
    // At a phase start, the pattern of the last phase that began mixed is tried first among
    // the attempts of its signs, with its stick end next to the edge that slips against the phase
    // where it was then (`PhaseStart`). The standard pattern's attempts still come first: where
    // both converge to states that pass the checks (the edge zone thinner than what the checks
    // resolve), the standard one is the state the step reports.
    let preferred = last_start
        .filter(|_| warm.is_none() && options.mixed_start_guesses)
        .map(|last| {
            let from = contact.unwrap_or((start.half_width, start.centre));
            (last.signs, last.guess(sign, guess, from))
        });
    if let Some(entry) = preferred {
        let at = plan
            .iter()
            .position(|p| p.0 == entry.0)
            .unwrap_or(plan.len());
        plan.insert(at, entry);
    }
    let mut attempts = Attempts::default();
    let scratch = LentMaps::lend();
    let last_link = RefCell::new(None);
    let reused = RefCell::new(Reused::default());
    let problem_for = |signs: (f64, f64)| StepProblem {
        model,
        disc,
        memory,
        base,
        signs,
        normal_load: start.normal_load,
        tangential_load,
        scratch: &scratch.0,
        last_link: &last_link,
        reused: &reused,
    };
    if let Some(step) = recalled.and_then(|r| recall(&problem_for, start, r, options)) {
        return Ok(step);
    }
    if let Some(step) = masing_return(&problem_for, start, sign, options, &mut attempts) {
        return Ok(step);
    }
    // Every attempt is made with the fast quasi-Newton iteration first; the jumps above are
    // where it can miss a root that Newton's method finds, so Newton's method is the fallback.
    'attempts: for newton in [false, true] {
        for &(signs, guess) in &plan {
            if attempts.stalled.is_some() {
                break 'attempts;
            }
            let problem = problem_for(signs);
            let method = match warm {
                _ if newton => Method::Newton,
                Some(w) if w.signs == signs => Method::Broyden(Some(w.jacobian)),
                Some(_) => Method::Coarse,
                None => Method::Broyden(None),
            };
            // Within a phase the prediction continues the warm start's slip signs only.
            let first = guess == guesses_in[0] || preferred == Some((signs, guess));
            let contact = contact.filter(|_| first && warm.is_none_or(|w| w.signs == signs));
            match solve_geometry(&problem, start, start, (guess, contact), method, options) {
                Ok(step) => return Ok(step),
                Err(failed) => {
                    let retry = failed.stalled.is_some() && method.within_phase();
                    attempts.record(failed);
                    // A stall from a carried (or coarse) Jacobian is tried once more from a
                    // fresh finite-difference one before the stalled iterate is taken (default
                    // history at M = 64, 20 steps per segment, the step at −0.075 ηP of the
                    // second cycle: stalled at 1.4e−6 after 65 evaluations, converged in 10,
                    // 7e−6 a from the stalled state; the two other stalls of the batch in
                    // `docs/performance.md` stay stalled, at 66 and 73 more evaluations).
                    if retry {
                        let fresh = Method::Broyden(None);
                        let again = (guess, contact);
                        if let Ok(step) =
                            solve_geometry(&problem, start, start, again, fresh, options)
                        {
                            return Ok(step);
                        }
                    }
                }
            }
        }
    }
    // No attempt converged: the admissible stalled iterate, if any.
    match attempts.stalled {
        Some(step) => Ok(*step),
        None => Err(attempts.first_failure.expect("at least one attempt")),
    }
}

/// The recalled state's geometry, from its own coefficients and Jacobian; `None` (and nothing
/// recorded: the step's own attempts follow) when its first residual exceeds
/// [`RECALL_RESIDUAL`], i.e. the problem is not the earlier one's.
fn recall<'a>(
    problem_for: &dyn Fn((f64, f64)) -> StepProblem<'a>,
    start: &ContactState,
    recalled: &Recalled,
    options: SlipOptions,
) -> Option<SlipStep> {
    let state = &recalled.state;
    let zone = state.traction.stick.as_ref()?;
    let guess = ((zone.lo, zone.hi), Some((state.half_width, state.centre)));
    let problem = problem_for(recalled.warm.signs);
    let method = Method::Recall(recalled);
    solve_geometry(&problem, start, state, guess, method, options).ok()
}

/// Masing's memory: when the load returns to the load of a remembered turning point whose
/// stick zone lies inside the current one, that turning state solves the step again (inside
/// its zone the memory is the one it stuck with, and outside it the step slips as it did).
/// The stretch between the current stick ends and the remembered ones is then exactly at the
/// friction limit, so the residuals are flat in the stick ends there: the continuation from
/// the previous step lands on an M-dependent point of that stretch (the same p, q and g, with
/// the stretch labelled stuck) or does not converge. The turning state is therefore tried
/// first, from its own geometry; the smallest stick zone is the canonical one. `None` when no
/// remembered turning point applies or none converges (failures go to `attempts`).
fn masing_return<'a>(
    problem_for: &dyn Fn((f64, f64)) -> StepProblem<'a>,
    start: &ContactState,
    sign: f64,
    options: SlipOptions,
    attempts: &mut Attempts,
) -> Option<SlipStep> {
    let (lo0, hi0) = start
        .traction
        .stick
        .as_ref()
        .map_or((f64::NEG_INFINITY, f64::INFINITY), |z| (z.lo, z.hi));
    let probe = problem_for((sign, sign));
    let limit = probe.model.friction * start.normal_load;
    for turning in probe
        .memory
        .states_at_load(probe.tangential_load, 1e-9 * limit)
    {
        let Some(zone) = turning.traction.stick.as_ref() else {
            continue;
        };
        let signs = (turning.traction.left_sign, turning.traction.right_sign);
        if signs != (sign, sign) || zone.lo < lo0 || zone.hi > hi0 {
            continue;
        }
        let method = Method::Broyden(None);
        let guess = ((zone.lo, zone.hi), None);
        match solve_geometry(&probe, start, &turning, guess, method, options) {
            Ok(step) => return Some(step),
            Err(failed) => attempts.record(failed),
        }
    }
    None
}

/// Finite-difference Jacobian of the residuals at `g` (the inherited correction of the base
/// point is kept so that the differences do not straddle a switch of the chain).
#[allow(clippy::needless_range_loop)]
fn fd_jacobian(
    problem: &StepProblem<'_>,
    g: &Geometry,
    r: &[f64; 4],
    state: &ContactState,
) -> Result<[[f64; 4]; 4], SolveFailure> {
    // Steps well above evaluation noise, well inside the contact (the residuals have
    // square-root behaviour at its ends).
    let room = (g.lo - (g.c - g.a)).min(g.c + g.a - g.hi);
    let d = (1e-6 * g.a).min(0.1 * room).max(1e-10 * g.a);
    let chosen = state
        .traction
        .stick
        .as_ref()
        .and_then(|z| z.inherited.clone());
    let mut jac = [[0.0; 4]; 4];
    for k in 0..4 {
        let mut gk = *g;
        let step = match k {
            0 => {
                gk.lo += d;
                d
            }
            1 => {
                gk.hi -= d;
                -d
            }
            2 => {
                gk.a += d;
                d
            }
            _ => {
                gk.c += d;
                d
            }
        };
        let (rk, ..) =
            problem.evaluate_with(&gk, state, chosen.clone(), JACOBIAN_INNER_TOLERANCE)?;
        for i in 0..4 {
            jac[i][k] = (rk[i] - r[i]) / step;
        }
    }
    Ok(jac)
}

/// The finite-difference Jacobian of the step's residuals at `g`, on the coarse companion grid
/// ([`Discretisation::coarse`]); `None` without one, or when an evaluation there fails. The
/// residuals are dimensionless and converge in M, and so does their dependence on the
/// geometry: the coarse Jacobian is the fine one to 1–3 % (measured at forward steps of the
/// default history at M = 72 … 512; the test `coarse_jacobian_is_near_the_fine_one` bounds
/// it), where the Jacobian carried from the previous step and updated by Broyden is off by
/// 3–8 % (the fine Jacobian itself moves by 7–9 % from one step to the next, and the
/// quasi-Newton steps, nearly parallel, correct it along one direction only). Its five
/// evaluations: the base point at the full inner tolerance, from `guess`'s traction, and four
/// differences.
fn coarse_jacobian(
    problem: &StepProblem<'_>,
    g: &Geometry,
    guess: &ContactState,
) -> Option<[[f64; 4]; 4]> {
    let maps = LentMaps::lend_from(&COARSE_MAPS);
    let coarse = StepProblem {
        disc: problem.disc.coarse()?,
        scratch: &maps.0,
        ..*problem
    };
    let (r, state, _) = coarse.evaluate(g, guess, INNER_TOLERANCE).ok()?;
    fd_jacobian(&coarse, g, &r, &state).ok()
}

/// A failed attempt: why, and its best iterate when that is an admissible state whose
/// residual stalled below [`SlipOptions::stall_tolerance`].
struct Failed {
    failure: SolveFailure,
    stalled: Option<Box<SlipStep>>,
}

impl From<SolveFailure> for Failed {
    fn from(failure: SolveFailure) -> Self {
        Self {
            failure,
            stalled: None,
        }
    }
}

/// The outcomes of a step's attempts: the first failure (reported when nothing is accepted)
/// and the first admissible stalled iterate (which ends the search).
#[derive(Default)]
struct Attempts {
    first_failure: Option<SolveFailure>,
    stalled: Option<Box<SlipStep>>,
}

impl Attempts {
    fn record(&mut self, failed: Failed) {
        self.first_failure.get_or_insert(failed.failure);
        if self.stalled.is_none() {
            self.stalled = failed.stalled;
        }
    }
}

/// How the geometry is iterated.
#[derive(Debug, Clone, Copy)]
enum Method<'a> {
    /// Secant updates within the evaluation budget (projected within a phase, Broyden's at a
    /// phase start: [`Method::within_phase`]), from the given Jacobian (the previous step's)
    /// or, with [`SlipOptions::coarse_jacobian`] and a coarse grid, from the coarse grid's at
    /// the first iterate; without one, from a finite-difference Jacobian.
    Broyden(Option<[[f64; 4]; 4]>),
    /// Secant updates within a phase for slip signs other than the previous step's (whose
    /// Jacobian does not apply): from the coarse grid's Jacobian at the first iterate with
    /// [`SlipOptions::coarse_jacobian`] and a coarse grid, else a finite-difference one.
    Coarse,
    /// Newton's method with a finite-difference Jacobian at every iterate and five times the
    /// evaluation budget: slower, and the fallback where the quasi-Newton attempts all fail.
    Newton,
    /// Secant updates from a recalled step's Jacobian, the first residual solved at the full
    /// inner tolerance (from the recalled coefficients, a pass or two), and given up at once
    /// when that residual exceeds [`RECALL_RESIDUAL`].
    Recall(&'a Recalled),
}

impl Method<'_> {
    /// Whether the attempt is within a phase and starts from a Jacobian that applies to its
    /// slip signs or from the coarse grid's (not a phase start, not a recalled step, not
    /// Newton's fallback): where the coarse grid's Jacobian is taken and a stall is tried once
    /// more from a finite-difference one.
    fn within_phase(&self) -> bool {
        matches!(self, Method::Broyden(Some(_)) | Method::Coarse)
    }
}

/// Newton's method on the geometry with rank-one secant updates: the Jacobian is taken
/// from the coarse grid or from `hint` (the previous step's, when the sign pattern is the
/// same; see [`Method::Broyden`]) or by finite differences, updated after every accepted
/// step, and recomputed by finite differences only when a quasi-Newton direction fails the
/// line search. The iteration begins with the stick ends `guess` and the half-width, centre
/// and traction of `from`; `start` is the previous step, against which the slip direction is
/// checked.
#[allow(clippy::needless_range_loop, clippy::too_many_arguments)]
fn solve_geometry(
    problem: &StepProblem<'_>,
    start: &ContactState,
    from: &ContactState,
    (guess, contact): ((f64, f64), Option<(f64, f64)>),
    method: Method<'_>,
    options: SlipOptions,
) -> Result<SlipStep, Failed> {
    let (hint, quasi_newton) = match method {
        Method::Broyden(hint) => (hint, true),
        Method::Coarse => (None, true),
        Method::Recall(recalled) => (Some(recalled.warm.jacobian), true),
        Method::Newton => (None, false),
    };
    // The recalled step and its checks, at an iterate that repeats it (`Recalled`).
    let repeated = |g: &Geometry| match method {
        Method::Recall(recalled) => recalled.repeated_at(g).map(|checks| (recalled, checks)),
        _ => None,
    };
    let model = problem.model;
    let (a0, c0) = contact.unwrap_or((from.half_width, from.centre));
    let clamp_lo = |lo: f64| lo.max(c0 - a0 * (1.0 - 1e-9));
    let clamp_hi = |hi: f64| hi.min(c0 + a0 * (1.0 - 1e-9));
    let mut g = Geometry {
        lo: clamp_lo(guess.0),
        hi: clamp_hi(guess.1),
        a: a0,
        c: c0,
    };
    if !problem.valid(&g) {
        g.lo = c0 - 0.5 * a0;
        g.hi = c0 + 0.5 * a0;
    }
    // A residual from a loose inner solve is solved again at the full inner tolerance
    // before its iterate can be accepted.
    let solve_fully = |g: &Geometry, s: &ContactState| problem.evaluate(g, s, INNER_TOLERANCE);
    // The first residual of an attempt is a trial iterate's whose size is not known yet: it is
    // solved to the loosest inner tolerance (an accepted residual is solved again at the
    // full tolerance anyway, so this saves inner passes and leaves the states unchanged).
    let recalled = matches!(method, Method::Recall(_));
    let first_tolerance = if recalled {
        INNER_TOLERANCE
    } else {
        LOOSEST_INNER_TOLERANCE
    };
    let (mut r, mut state, mut tight) = problem.evaluate(&g, from, first_tolerance)?;
    if recalled && norm(&r) > RECALL_RESIDUAL {
        return Err(SolveFailure::NoConvergence {
            what: "recalled step",
            iterations: 1,
            residual: norm(&r),
        }
        .into());
    }
    let mut evaluations = 1;
    let mut jac = hint;
    // Within a phase the coarse grid's Jacobian at the first iterate replaces the carried one
    // (`coarse_jacobian`). Its evaluations are not counted: they are the coarse grid's. It
    // saves residual evaluations because within a phase the geometry changes little, so the
    // coarse Jacobian at the current iterate is closer than the carried one. At a phase start
    // the fine one is kept: there a coarse Jacobian can steer the iteration to another
    // admissible state.
    if options.coarse_jacobian && method.within_phase() {
        jac = coarse_jacobian(problem, &g, &state).or(jac);
    }
    let mut fresh = false;
    // The state at an accepted iterate `g`: φ0, the shape table and the checks.
    let accept = |mut state: ContactState,
                  g: &Geometry,
                  iterations: usize,
                  evaluations: usize,
                  residual: f64,
                  jac: Option<[[f64; 4]; 4]>|
     -> Result<SlipStep, SolveFailure> {
        let repeated = repeated(g);
        if state.split.conducting
            && !matches!(
                model.electrode,
                super::Electrode::ConductingPotential { .. }
            )
        {
            // φ0 of the accepted state (charge control; the moment does not feed back), or
            // the recalled state's when this is that state again.
            (state.charge, state.potential) = match repeated {
                Some((recalled, _)) => (recalled.state.charge, recalled.state.potential),
                None => {
                    let j_q = arcsine_moment(&state);
                    electric_resultants(model, g.a, problem.normal_load, j_q)
                }
            };
        }
        // The accepted state is evaluated many times from here on (checks, increments,
        // memory): tabulate its shape quadrature once, and drop an own correction that is
        // round-off (a return to a remembered state inherits that state whole and adds
        // nothing; its own series, about 1e−16 of ηp0, would otherwise cost a Clenshaw sum at
        // every later evaluation of every state whose chain holds it, one more per cycle).
        state.tabulate_shape();
        state.drop_negligible_correction(model.friction);
        let admissibility = match repeated {
            Some((_, checks)) => checks,
            None => assess_step(model, start, &state),
        };
        check(&admissibility, options.admissibility)?;
        Ok(SlipStep {
            state,
            iterations,
            newton_iterations: evaluations,
            residual,
            admissibility,
            jacobian: jac.unwrap_or([[0.0; 4]; 4]),
            repeated: repeated.is_some(),
        })
    };
    // The projected update within a phase; at a phase start Broyden's (there the iteration's
    // path decides which of several admissible states it reaches: tried there too, the first
    // step of a PZT-4 first loading at M = 128 reached another state, 8e−5 a away).
    let projected =
        options.projected_updates && (method.within_phase() || matches!(method, Method::Recall(_)));
    let mut directions = SecantDirections::default();
    let mut iterations = 0;
    for iter in 0..options.max_iterations {
        iterations = iter;
        let size = norm(&r);
        if size < options.tolerance && !tight {
            // Converged on a loose inner solve: confirm at the full inner tolerance (from the
            // loose solution, a pass or two).
            (r, state, tight) = solve_fully(&g, &state)?;
            evaluations += 1;
            continue;
        }
        if size < options.tolerance {
            return Ok(accept(state, &g, iter, evaluations, size, jac)?);
        }
        // Newton's fallback gets a larger budget: it needs 5 evaluations per iteration. An
        // attempt that is already within 1e4 of the tolerance is converging (attempts without
        // a root wander at large residuals) and may take twice the budget: at the first step
        // after the reversal of the default history at M = 128 the mixed state converged
        // linearly to 5e−12 in the 61 evaluations allowed, and the next attempt found the same
        // state after 38 more.
        let near = size < 1e4 * options.tolerance;
        let budget =
            if quasi_newton { 1 } else { 5 } * options.max_evaluations * if near { 2 } else { 1 };
        if evaluations > budget {
            break;
        }
        let j = match jac {
            Some(j) => j,
            None => {
                evaluations += 4;
                fresh = true;
                directions = SecantDirections::default();
                fd_jacobian(problem, &g, &r, &state)?
            }
        };
        let Some(dx) = solve4(j, r) else {
            if fresh {
                break;
            }
            jac = None;
            continue;
        };
        let mut alpha = 1.0;
        let mut accepted = None;
        for _ in 0..if fresh { 30 } else { 6 } {
            let gn = Geometry {
                lo: g.lo + alpha * dx[0],
                hi: g.hi + alpha * dx[1],
                a: g.a + alpha * dx[2],
                c: g.c + alpha * dx[3],
            };
            if problem.valid(&gn) {
                // Near the tolerance the trial is solved fully, so that it can be accepted as
                // it is (a loose one below the tolerance would be evaluated again, one fine
                // evaluation more).
                let inner = if near {
                    INNER_TOLERANCE
                } else {
                    inner_tolerance(size)
                };
                let (rn, sn, full) = problem.evaluate(&gn, &state, inner)?;
                evaluations += 1;
                if norm(&rn) < (1.0 - 1e-4 * alpha) * size {
                    accepted = Some((gn, rn, sn, alpha, full));
                    break;
                }
            }
            alpha *= 0.5;
        }
        let Some((gn, rn, sn, alpha, full)) = accepted else {
            if fresh {
                break;
            }
            jac = None;
            continue;
        };
        // The secant update with the step taken and the change of the residuals.
        let step = dx.map(|v| alpha * v);
        let direction = if projected {
            directions.direction(step)
        } else {
            step
        };
        let change = std::array::from_fn(|i| rn[i] - r[i]);
        jac = quasi_newton.then(|| secant_update(j, step, change, direction));
        fresh = false;
        g = gn;
        r = rn;
        state = sn;
        tight = full;
    }
    // Every accepted iterate lowered the residual, so the last one is the best. A stalled
    // iterate that may be accepted is first solved at the full inner tolerance (its inner
    // solve may have stopped at 1e−3 of the residual before it).
    let mut size = norm(&r);
    if size < options.stall_tolerance && !tight {
        (r, state, _) = solve_fully(&g, &state)?;
        evaluations += 1;
        size = norm(&r);
    }
    let stalled = (size < options.stall_tolerance)
        .then(|| accept(state, &g, iterations, evaluations, size, jac).ok())
        .flatten()
        .map(Box::new);
    Err(Failed {
        failure: SolveFailure::NoConvergence {
            what: "tangential step (Newton on stick ends, a, c)",
            iterations: evaluations,
            residual: size,
        },
        stalled,
    })
}

/// The secant update of `j` along `direction` d for the step s taken and the change y of the
/// residuals: `J + (y − J s) dᵀ/(dᵀ s)`. The updated Jacobian maps s to y; on vectors
/// orthogonal to d it acts as `j` did. With d = s this is Broyden's update.
#[allow(clippy::needless_range_loop)]
fn secant_update(
    j: [[f64; 4]; 4],
    step: [f64; 4],
    change: [f64; 4],
    direction: [f64; 4],
) -> [[f64; 4]; 4] {
    let scale: f64 = (0..4).map(|k| direction[k] * step[k]).sum();
    let mut updated = j;
    for i in 0..4 {
        let predicted: f64 = (0..4).map(|k| j[i][k] * step[k]).sum();
        let miss = change[i] - predicted;
        for k in 0..4 {
            updated[i][k] += miss * direction[k] / scale;
        }
    }
    updated
}

/// The directions of an attempt's accepted steps since its last restart, orthonormal: the
/// projected secant update (Gay and Schnabel, 1978) updates the Jacobian along the part of each
/// new step orthogonal to them, so that it keeps mapping the earlier steps to their changes
/// of the residuals as well as the new one. On a linear problem the Jacobian is exact after
/// four independent steps, where Broyden's update, which updates along the step itself,
/// spoils the earlier secant conditions. Quasi-Newton steps within a phase are nearly
/// parallel (mostly along the stick end that moves), so the update restarts, as Broyden's,
/// when a step has less than a tenth of its length outside the earlier directions (or all
/// four are taken; a tenth took the fewest evaluations over the regression runs). Against
/// Broyden's update it saves residual evaluations and lets steps converge that would
/// otherwise stall near the tolerance.
#[derive(Debug, Default)]
struct SecantDirections(Vec<[f64; 4]>);

/// The fraction of a step's length outside the earlier directions below which
/// [`SecantDirections`] restarts.
const RESTART_FRACTION: f64 = 0.1;

impl SecantDirections {
    /// The direction of the update for `step`, which joins the directions.
    fn direction(&mut self, step: [f64; 4]) -> [f64; 4] {
        let mut rest = step;
        for d in &self.0 {
            let along: f64 = (0..4).map(|k| d[k] * step[k]).sum();
            for k in 0..4 {
                rest[k] -= along * d[k];
            }
        }
        let length2 = |v: &[f64; 4]| v.iter().map(|x| x * x).sum::<f64>();
        if length2(&rest) < RESTART_FRACTION.powi(2) * length2(&step) || self.0.len() == 4 {
            self.0.clear();
            rest = step;
        }
        let length = length2(&rest).sqrt();
        self.0.push(rest.map(|v| v / length));
        rest
    }
}

fn check(adm: &StepAdmissibility, tol: f64) -> Result<(), SolveFailure> {
    let [stick_at, slip_at, pressure_at] = adm.worst_at;
    super::first_violation(&[
        (
            "p ≥ 0",
            -adm.min_pressure,
            tol,
            adm.min_pressure,
            pressure_at,
        ),
        (
            "|q| ≤ η p in the stick zone",
            adm.stick_excess,
            tol,
            adm.stick_excess,
            stick_at,
        ),
        (
            "slip in the slip zones must oppose the friction",
            adm.slip_reversal,
            tol.max(1e-2),
            adm.slip_reversal,
            slip_at,
        ),
    ])
}

/// The admissibility measures of a step from `old` to `new` (module docs).
pub fn assess_step(
    model: &ContactModel,
    old: &ContactState,
    new: &ContactState,
) -> StepAdmissibility {
    let stick = new.traction.stick.as_ref().expect("slip state");
    let eta = model.friction;
    let (c, a) = (new.centre, new.half_width);
    let p0 = new.pressure_at(c);
    let mut out = StepAdmissibility {
        stick_excess: f64::NEG_INFINITY,
        slip_reversal: f64::NEG_INFINITY,
        min_pressure: 1.0,
        worst_at: [f64::NAN; 3],
    };
    let (mut p, mut q) = (Vec::new(), Vec::new());
    let xs: Vec<f64> = (1..400)
        .map(|i| c + a * (-1.0 + 2.0 * i as f64 / 400.0))
        .collect();
    new.pressures_into(&xs, &mut p);
    for (&x, p) in xs.iter().zip(&p) {
        let ratio = p / p0;
        if ratio < out.min_pressure {
            out.min_pressure = ratio;
            out.worst_at[2] = x;
        }
    }
    // The end itself exactly: a point rounded just inside an end would see q̃'s square root of
    // the rounding error (about 2e−9 η p0 at 1e−21 m).
    let xs: Vec<f64> = (0..=200)
        .map(|i| {
            if i == 200 {
                stick.hi
            } else {
                stick.lo + (stick.hi - stick.lo) * i as f64 / 200.0
            }
        })
        .collect();
    new.pressures_into(&xs, &mut p);
    new.tractions_with(&xs, &p, &mut q);
    for ((&x, p), q) in xs.iter().zip(&p).zip(&q) {
        let excess = (q.abs() - eta * p) / (eta * p0);
        if excess > out.stick_excess {
            out.stick_excess = excess;
            out.worst_at[0] = x;
        }
    }
    // Slip increments at points of each slip zone, by the check's rule
    // ([`super::slip_check_rule_nodes`]: the sign is checked to 1e−2 of the largest slip,
    // the rule gives it to 1.2e−4 or better).
    let nodes = super::slip_check_rule_nodes(new.pressure.beta.len());
    let slips = slip_work_densities(model, old, new, nodes);
    let largest = slips
        .iter()
        .fold(0.0f64, |m, (_, _, s)| m.max(s.abs()))
        .max(1e-300);
    for (x, zs, s) in slips {
        let reversal = zs * s / largest;
        if reversal > out.slip_reversal {
            out.slip_reversal = reversal;
            out.worst_at[1] = x;
        }
    }
    out
}

/// The frictional work density per unit η, `p(x) Δs(x)`, with the slip sign of the zone, at
/// six points of each slip zone of `new` (¼, ½, ¾, 0.9, 0.97 and all of the way from the
/// stick end to the inner of the two contact ends: points that enter or leave the contact
/// have no slip increment). `Δs(x)` is the running integral of the strain change from the
/// stick end, by graded quadrature with `nodes` per piece, split at every point where either
/// state is not smooth ([`super::step_breakpoints`]) and at the six points.
fn slip_work_densities(
    model: &ContactModel,
    old: &ContactState,
    new: &ContactState,
    nodes: usize,
) -> Vec<(f64, f64, f64)> {
    let stick = new.traction.stick.as_ref().expect("slip state");
    let (c, a) = (new.centre, new.half_width);
    let mut d_strain =
        |xs: &[f64], out: &mut Vec<f64>| new.strain_changes_into(model, old, xs, out);
    let breaks = super::step_breakpoints(old, new);
    let mut slips = Vec::new();
    let zones = [
        (
            stick.hi,
            (c + a).min(old.centre + old.half_width),
            new.traction.right_sign,
        ),
        (
            stick.lo,
            (c - a).max(old.centre - old.half_width),
            new.traction.left_sign,
        ),
    ];
    for (from, to, zone_sign) in zones {
        let samples: Vec<f64> = [0.25, 0.5, 0.75, 0.9, 0.97, 1.0]
            .iter()
            .map(|f| from + f * (to - from))
            .collect();
        let (left, right) = (from.min(to), from.max(to));
        let mut pts: Vec<f64> = breaks
            .iter()
            .copied()
            .filter(|x| *x > left && *x < right)
            .collect();
        pts.extend(&samples);
        pts.extend([left, right]);
        let table = super::graded_cumulative(pts, nodes, None, &mut d_strain);
        for x in samples {
            // ∫ from `left` to x: the nodes of the pieces before x (x is a piece end).
            let before: f64 = table
                .nodes
                .iter()
                .filter(|n| n.0 < x)
                .map(|n| n.1 * n.2)
                .sum();
            let slip = if to > from {
                before
            } else {
                before - table.total
            };
            slips.push((x, zone_sign, slip * new.pressure_at(x)));
        }
    }
    slips
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The stick rows from the one matrix of `T_n` values equal the density and Cauchy rows
    /// they replace (`√(1−τ²) U_{n−1}`, `T_n/√(1−τ²)`, `−T_n`), summed directly, for series
    /// of the solver's length with slowly decaying coefficients, at stick points across the
    /// contact and 1e−4 from its ends (where `1/√(1−τ²)` is 71). Measured: 9.3e−16 of the
    /// sum of the terms' sizes at worst; bound 1e−14.
    #[test]
    fn stick_terms_equal_the_density_and_cauchy_rows() {
        use crate::quadrature::UnboundedSeries;
        let m = 128;
        let taus = [-0.9999, -0.998, -0.6, -0.01, 0.0, 0.35, 0.9, 0.9999];
        let beta: Vec<f64> = (1..=m).map(|n| (0.9 * n as f64).sin() / n as f64).collect();
        let gamma: Vec<f64> = (0..m)
            .map(|n| (1.3 * n as f64 + 0.4).cos() / (n + 1) as f64)
            .collect();
        let (local, eta_s, w) = (0.37, -0.25, 1.9);
        let mut worst: f64 = 0.0;
        for shape in [Some(eta_s), None] {
            let mut maps = InnerMaps::default();
            maps.stick_t.refill(m + 2, &taus, |t| [t, 1.0, 1.0]);
            maps.stick_root = taus.iter().map(|t| 1.0 / (1.0 - t * t).sqrt()).collect();
            maps.coefficients = Coefficients {
                local_over_y11: local,
                shape,
                charge: Some(w),
            };
            let mut buffers = StickSums {
                coefficients: [vec![0.0; m + 2], vec![0.0; m + 2]],
                sums: [vec![0.0; taus.len()], vec![0.0; taus.len()]],
            };
            let (mut srhs, mut cauchy) = (vec![0.0; taus.len()], vec![0.0; taus.len()]);
            maps.stick_terms(&beta, &gamma, &mut buffers, &mut srhs, &mut cauchy);
            let mut row = vec![0.0; m];
            for (i, &t) in taus.iter().enumerate() {
                let mut terms = Vec::new();
                BoundedSeries::density_row(t, &mut row);
                terms.extend(row.iter().zip(&beta).map(|(r, b)| local * r * b));
                UnboundedSeries::density_row(t, &mut row);
                terms.extend(row.iter().zip(&gamma).map(|(r, g)| w * r * g));
                BoundedSeries::cauchy_row(t, &mut row);
                let h: Vec<f64> = row.iter().zip(&beta).map(|(r, b)| r * b).collect();
                let size = |v: &[f64]| v.iter().map(|x| x.abs()).sum::<f64>();
                if let Some(eta_s) = shape {
                    terms.extend(h.iter().map(|v| -eta_s * v));
                } else {
                    let direct: f64 = h.iter().sum();
                    worst = worst.max((cauchy[i] - direct).abs() / size(&h));
                }
                let direct: f64 = terms.iter().sum();
                worst = worst.max((srhs[i] - direct).abs() / size(&terms));
            }
        }
        assert!(worst < 1e-14, "{worst:.2e}");
    }

    /// One load step of scenario `sc` by the driver (`advance`, default options).
    fn advance_driver(
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
    fn forward_problem<'a>(
        sc: &'a crate::scenario::Scenario,
        disc: &'a Discretisation,
        driver: &'a crate::history::DriverState,
        base: Option<&'a Arc<StickZone>>,
        maps: &'a RefCell<InnerMaps>,
        (last_link, reused): (&'a RefCell<Option<Arc<Inherited>>>, &'a RefCell<Reused>),
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
            last_link,
            reused,
        }
    }

    /// The end probes keep clear of a remembered stick end near a new one: a quarter and a half
    /// of its distance from the end when it lies within `4 END_PROBE h`, unless that is closer
    /// to the end than the series' first node; elsewhere `END_PROBE h` and twice that.
    #[test]
    fn end_probes_keep_clear_of_a_remembered_end() {
        let g = Geometry {
            lo: -1.0,
            hi: 1.0,
            a: 1.2,
            c: 0.0,
        };
        let m = 64;
        let zone = StickZone::new(g.lo, g.hi, BoundedSeries::default(), 0.0);
        let first_node = 1.0 - (std::f64::consts::PI / 65.0).cos();
        // h = 1: a remembered end 0.015 inside the right end, one 0.5 inside the left.
        let probes = EndProbes::new(&g, m, &zone, &[-0.5, 1.0 - 0.015]);
        let close = |x: f64, y: f64| (x - y).abs() < 1e-15;
        let d = probes.scale.map(|s| s * s);
        assert!(close(d[0], END_PROBE) && close(d[1], 0.015 / 4.0));
        assert!(close(probes.points[2], 1.0 - 0.015 / 4.0));
        assert!(close(probes.points[3], 1.0 - 0.015 / 2.0));
        // A quarter of the distance below the first node: the standard probes.
        let probes = EndProbes::new(&g, m, &zone, &[1.0 - 3.0 * first_node]);
        assert!(probes.scale.iter().all(|&s| close(s * s, END_PROBE)));
        // Nothing remembered nearby.
        let probes = EndProbes::new(&g, m, &zone, &[]);
        assert!(probes.scale.iter().all(|&s| close(s * s, END_PROBE)));
        // The extrapolation is exact for k √r (1 + c r) at either spacing.
        let q = |r: f64| 3.0 * r.sqrt() * (1.0 + 0.7 * r);
        let probes = EndProbes::new(&g, m, &zone, &[1.0 - 0.015]);
        let [left, right] = probes.scaled_roots(|x| q((x - g.lo).min(g.hi - x)));
        let (kl, kr) = (left / probes.scale[0], right / probes.scale[1]);
        assert!(
            (kl - 3.0).abs() < 1e-12 && (kr - 3.0).abs() < 1e-12,
            "{kl} {kr}"
        );
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

    /// On a linear map `y = A s` the projected secant update reproduces A after four
    /// independent steps (the fourth step's update keeps the three earlier secant conditions),
    /// where Broyden's, from the same start and steps, is still off; a step with less than a
    /// tenth of its length outside the earlier directions restarts them.
    #[test]
    fn projected_updates_recover_a_linear_map_in_four_steps() {
        let a = [
            [4.0, -1.0, 0.5, 2.0],
            [1.0, 3.0, -2.0, 0.0],
            [0.0, 1.5, 5.0, -1.0],
            [-2.0, 0.0, 1.0, 6.0],
        ];
        let apply = |m: &[[f64; 4]; 4], v: [f64; 4]| -> [f64; 4] {
            std::array::from_fn(|i| (0..4).map(|k| m[i][k] * v[k]).sum())
        };
        // Neither orthogonal nor parallel to each other.
        let steps = [
            [1.0, 0.2, 0.0, 0.1],
            [0.8, 1.0, 0.3, 0.0],
            [0.5, -0.4, 1.0, 0.2],
            [0.3, 0.6, -0.5, 1.0],
        ];
        let start = [
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ];
        let (mut projected, mut broyden) = (start, start);
        let mut directions = SecantDirections::default();
        for s in steps {
            let y = apply(&a, s);
            projected = secant_update(projected, s, y, directions.direction(s));
            broyden = secant_update(broyden, s, y, s);
        }
        let miss = |j: &[[f64; 4]; 4]| {
            (0..4)
                .flat_map(|i| (0..4).map(move |k| (i, k)))
                .map(|(i, k)| (j[i][k] - a[i][k]).abs())
                .fold(0.0, f64::max)
        };
        println!(
            "projected {:e}, Broyden {:e}",
            miss(&projected),
            miss(&broyden)
        );
        assert!(miss(&projected) < 1e-12, "{:e}", miss(&projected));
        assert!(miss(&broyden) > 0.1, "{:e}", miss(&broyden));
        // The four directions are taken: the next step restarts them, and its update is
        // Broyden's (along the step itself).
        let bits = |v: [f64; 4]| v.map(f64::to_bits);
        let fifth = [1.0, 1.0, 1.0, 1.0];
        assert_eq!(bits(directions.direction(fifth)), bits(fifth));
        assert_eq!(directions.0.len(), 1);
        // A step with 4 % of its length outside the one direction restarts them too; the next
        // one, with 15 % outside the new direction, does not: its update is along that part.
        let near = [1.0, 1.0, 1.0, 1.1];
        assert_eq!(bits(directions.direction(near)), bits(near));
        let turned = directions.direction([1.0, 1.0, 1.0, 1.5]);
        let along = (3.0 + 1.1 * 1.5) / (3.0 + 1.1 * 1.1);
        let expected = [1.0 - along, 1.0 - along, 1.0 - along, 1.5 - 1.1 * along];
        assert!(
            turned
                .iter()
                .zip(expected)
                .all(|(t, e)| (t - e).abs() < 1e-15),
            "{turned:?}"
        );
        assert_eq!(directions.0.len(), 2);
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

    /// `solve_small` on every size up to `SMALL`: a system with a known solution whose first
    /// pivot is zero (so rows must be swapped) is solved to round-off, and a singular one is
    /// refused.
    #[test]
    fn small_systems_are_solved_with_pivoting() {
        for n in 1..=SMALL {
            let want: Vec<f64> = (0..n).map(|i| 1.0 + 0.5 * i as f64).collect();
            let mut rows = [[0.0; SMALL + 1]; SMALL];
            for (i, row) in rows.iter_mut().take(n).enumerate() {
                for (j, a) in row.iter_mut().take(n).enumerate() {
                    // Zero on the first diagonal entry (n > 1), diagonally heavy elsewhere.
                    *a = if i == j && (i > 0 || n == 1) {
                        4.0 + i as f64
                    } else if i == j {
                        0.0
                    } else {
                        1.0 / (1.0 + (i + 2 * j) as f64)
                    };
                }
                row[n] = (0..n).map(|j| row[j] * want[j]).sum();
            }
            let got = solve_small(rows, n).expect("regular system");
            for (g, w) in got.iter().zip(&want) {
                assert!((g - w).abs() < 1e-13, "n = {n}: {g} against {w}");
            }
            if n > 1 {
                let mut singular = rows;
                singular[1] = singular[0];
                assert!(
                    solve_small(singular, n).is_none(),
                    "n = {n}: singular accepted"
                );
            }
        }
    }

    /// A finite-difference Jacobian's evaluations take the parts their base point shares with
    /// them from [`Reused`] (the sample parts when a stick end moves, the stick parts when the
    /// contact moves), and each such evaluation is bit for bit the one made without them.
    #[test]
    fn reused_parts_leave_the_evaluations_unchanged() {
        use crate::contact::normal::{NormalOptions, solve_normal};
        use crate::history::{DriverState, LoadPoint};
        let sc = crate::scenario::default_scenario();
        let disc = Discretisation::new(64);
        let normal =
            solve_normal(&sc.model, &disc, sc.normal_load, NormalOptions::default()).unwrap();
        let mut driver = DriverState::after_normal_loading(&normal);
        for (step, f) in [0.1, 0.2].into_iter().enumerate() {
            let q = f * sc.model.friction * sc.normal_load;
            let point = LoadPoint {
                step: step + 1,
                t: (step + 1) as f64,
                q,
            };
            advance_driver(&sc, &disc, &mut driver, point);
        }
        let base = normal.state.traction.stick.clone().map(Arc::new);
        let state = &driver.state;
        let g = Geometry::of(state).expect("slip state");
        let link = state
            .traction
            .stick
            .as_ref()
            .and_then(|z| z.inherited.clone());
        let maps = LentMaps::lend();
        let (last_link, shared) = (RefCell::new(None), RefCell::new(Reused::default()));
        let with_shared = forward_problem(
            &sc,
            &disc,
            &driver,
            base.as_ref(),
            &maps.0,
            (&last_link, &shared),
        );
        let evaluate = |p: &StepProblem<'_>, g: &Geometry| {
            let (r, s, _) = p
                .evaluate_with(g, state, link.clone(), INNER_TOLERANCE)
                .unwrap();
            (
                r.map(f64::to_bits),
                s.pressure
                    .beta
                    .iter()
                    .map(|b| b.to_bits())
                    .collect::<Vec<_>>(),
            )
        };
        evaluate(&with_shared, &g);
        let d = 1e-6 * g.a;
        let moves = [Geometry { lo: g.lo + d, ..g }, Geometry { a: g.a + d, ..g }];
        for moved in moves {
            let fresh = RefCell::new(Reused::default());
            let with_fresh = StepProblem {
                reused: &fresh,
                ..with_shared
            };
            assert!(evaluate(&with_shared, &moved) == evaluate(&with_fresh, &moved));
        }
        // The base point's sample parts served the moved stick end, its stick parts the moved
        // contact: two entries of each kind, not three.
        let kept = shared.borrow();
        assert_eq!((kept.stick.len(), kept.samples.len()), (2, 2));
    }

    /// The coarse grid's Jacobian of a forward step (default scenario, first loading, at
    /// 0.3 ηP) is the fine grid's to within a few per cent, and nearer to it than the fine
    /// Jacobian of the previous step (0.25 ηP), which is what carrying a Jacobian from step to
    /// step starts from. The measure is the largest entry of `J_start⁻¹ J − I`, the factor by
    /// which a quasi-Newton step from `J_start` misses. Measured at M = 72, 80, 96, 112, 128,
    /// 192 and 256: coarse 9.0e−3, 1.6e−2, 2.7e−2, 9.4e−3, 9.1e−3, 2.1e−2 and 9.2e−3; the
    /// previous step's 6.7e−2 to 8.7e−2, at least 2.5 times the coarse one. Bounds, at M = 80,
    /// 96 and 128: 4e−2, and twice the coarse one.
    #[test]
    fn coarse_jacobian_is_near_the_fine_one() {
        use crate::contact::normal::{NormalOptions, solve_normal};
        use crate::history::{DriverState, LoadPoint};
        let sc = crate::scenario::default_scenario();
        let limit = sc.model.friction * sc.normal_load;
        for m in [80, 96, 128] {
            let disc = Discretisation::new(m);
            let normal =
                solve_normal(&sc.model, &disc, sc.normal_load, NormalOptions::default()).unwrap();
            let mut driver = DriverState::after_normal_loading(&normal);
            let base = normal.state.traction.stick.clone().map(Arc::new);
            let maps = LentMaps::lend();
            // The fine Jacobian at the state the driver has reached, and the step's problem.
            let at_state = |driver: &DriverState| {
                let state = &driver.state;
                let g = Geometry::of(state).expect("slip state");
                let (last_link, reused) = (RefCell::new(None), RefCell::new(Reused::default()));
                let problem = forward_problem(
                    &sc,
                    &disc,
                    driver,
                    base.as_ref(),
                    &maps.0,
                    (&last_link, &reused),
                );
                let (r, solved, _) = problem.evaluate(&g, state, INNER_TOLERANCE).unwrap();
                // The state is a converged one: its residual again below the solver's tolerance.
                let tolerance = SlipOptions::default().tolerance;
                assert!(norm(&r) < tolerance, "M = {m}: residual {:e}", norm(&r));
                let fine = fd_jacobian(&problem, &g, &r, &solved).unwrap();
                let coarse = coarse_jacobian(&problem, &g, &solved).expect("coarse grid");
                (fine, coarse)
            };
            // Largest entry of `start⁻¹ j − I` (`solve4` solves `J dx = −r`).
            let miss = |start: [[f64; 4]; 4], j: [[f64; 4]; 4]| {
                (0..4)
                    .map(|k| {
                        let column = std::array::from_fn(|i| j[i][k]);
                        let x = solve4(start, column).expect("regular");
                        (0..4)
                            .map(|i| (-x[i] - if i == k { 1.0 } else { 0.0 }).abs())
                            .fold(0.0, f64::max)
                    })
                    .fold(0.0, f64::max)
            };
            let mut previous = None;
            for step in 1..=6 {
                let point = LoadPoint {
                    step,
                    t: step as f64,
                    q: 0.05 * step as f64 * limit,
                };
                advance_driver(&sc, &disc, &mut driver, point);
                if step >= 5 {
                    let (fine, coarse) = at_state(&driver);
                    if let Some(carried) = previous {
                        let (coarse_miss, carried_miss) = (miss(coarse, fine), miss(carried, fine));
                        println!("M = {m}: coarse {coarse_miss:.2e}, previous {carried_miss:.2e}");
                        assert!(coarse_miss < 4e-2, "M = {m}: coarse {coarse_miss:e}");
                        assert!(carried_miss > 2.0 * coarse_miss, "M = {m}");
                    }
                    previous = Some(fine);
                }
            }
        }
    }

    /// The slip check reads the sign of the slip increments (to 1e−2 of the largest slip of
    /// the step, `check`); its rule, `slip_check_rule_nodes`, against eight times the nodes
    /// over the first two phases of the default history (each step's six points in each slip
    /// zone, relative to the step's largest), with the states the driver reaches.
    #[test]
    fn the_slip_check_rule_reads_the_sign_to_a_small_error() {
        use crate::history::LoadPoint;
        let sc = crate::scenario::default_scenario();
        let disc = Discretisation::new(sc.collocation_points);
        let mut driver = crate::history::driver_after_normal_loading(&sc, &disc);
        let steps = sc.history.as_ref().expect("default history").steps();
        let nodes = crate::contact::slip_check_rule_nodes(disc.nodes());
        let mut worst: f64 = 0.0;
        for (i, &(_, t, q)) in steps.iter().take(30).enumerate() {
            let old = driver.state.clone();
            let point = LoadPoint { step: i + 1, t, q };
            advance_driver(&sc, &disc, &mut driver, point);
            let new = &driver.state;
            if new.traction.stick.is_none() || old.traction.stick.is_none() {
                continue;
            }
            let coarse = slip_work_densities(&sc.model, &old, new, nodes);
            let fine = slip_work_densities(&sc.model, &old, new, 8 * nodes);
            let largest = fine.iter().fold(0.0f64, |m, s| m.max(s.2.abs()));
            for (c, f) in coarse.iter().zip(&fine) {
                worst = worst.max((c.2 - f.2).abs() / largest);
            }
        }
        println!("worst slip check error {worst:.2e}");
        // Measured 2.3e−5 (and 1.2e−4 at worst over the regression batch).
        assert!(worst > 0.0 && worst < 1e-4, "{worst:e}");
    }

    /// The contact integrals' rule (`contact_piece_nodes`: fewer nodes on the short pieces)
    /// gives `ux` at a point of the stick zone and δn as four times the whole rule on every
    /// piece does, to a small fraction of their ranges over the first two phases of the default
    /// history at M = 128 (at M ≤ 64 the rule is the whole rule).
    #[test]
    fn the_contact_rule_gives_the_displacements_to_a_small_error() {
        use crate::history::LoadPoint;
        let sc = crate::scenario::default_scenario();
        let disc = Discretisation::new(128);
        let mut driver = crate::history::driver_after_normal_loading(&sc, &disc);
        let steps = sc.history.as_ref().expect("default history").steps();
        let fine = 4 * crate::contact::field_rule_nodes(disc.nodes());
        let (mut rule, mut reference) = (Vec::new(), Vec::new());
        for (i, &(_, t, q)) in steps.iter().take(30).enumerate() {
            let point = LoadPoint { step: i + 1, t, q };
            advance_driver(&sc, &disc, &mut driver, point);
            let s = &driver.state;
            // The contact centre at normal loading lies in every stick zone of these phases.
            rule.push(s.displacement_and_approach(&sc.model, 0.0));
            reference.push(s.displacement_and_approach_with(&sc.model, 0.0, |_, _| fine));
        }
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
