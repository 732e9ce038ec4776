//! The load-history driver: a piecewise-linear tangential load Q(t) walked step by step through
//! a closed set of solver states, with the strain memory stored at the start of every monotonic
//! phase (seed Section 4; `docs/formulation.md` §4).
//!
//! # States and transitions
//! [`Regime`] is closed: normal loading, stick (hold), forward slip, reverse slip. The next
//! regime is a pure function of the sign of ΔQ ([`next_regime`]): `ΔQ > 0` forward slip,
//! `ΔQ < 0` reverse slip, `ΔQ = 0` stick (nothing changes, the state is carried over). A phase
//! begins whenever the slip direction differs from the previous slip phase's (or at the first
//! slip step after normal loading): then the memory is recomputed from the current state over
//! the whole contact ([`Memory::committed`]). A hold between two segments of the same
//! direction does not start a new phase.
//!
//! # Steps
//! Each segment `(t0, Q0) → (t1, Q1)` is cut into `max(steps_per_segment, ⌈|ΔQ|/max_step⌉)`
//! equal steps. Each step is solved by [`solve_slip`] from the committed state and memory,
//! checked, and only then committed (trial, then commit). A failure stops the run with the
//! step, t, Q and regime; the steps already solved are kept by the caller (observer).
//!
//! A step's increments — Δδ at the anchor, the frictional dissipation and the works of P and
//! of the electric load ([`StepIncrements`], [`step_dissipation`]) — need only the step's two
//! states, and the next step needs none of them, so [`run_history`] computes them on a second
//! thread while it solves the next step ([`solve_step`], then [`finish_step`] in order);
//! [`continue_run`] does the same from any driver state, and [`advance`] does it
//! sequentially. The records are the same either way.
//!
//! # Warm start
//! Inside a phase the geometry of the step (stick ends, contact half-width and centre) is
//! extrapolated from the last three steps by the quadratic in Q through them (`predict`), and
//! the previous step's Jacobian starts the quasi-Newton iteration (after a step with mixed
//! slip signs the Mindlin–Deresiewicz guess below is tried first). At the
//! start of a phase the zones that already slip in the new direction keep slipping and the
//! others stick, with new slip zones of the Mindlin–Deresiewicz width
//! `a(1 − √(1 − |ΔQ|/(2ηP)))` at the ends that start to slip, and the contact centre moves by
//! ΔQ times dc/dQ of the previous phase's first step.
//!
//! # Recall of a repeated phase
//! The driver keeps the accepted steps of the current phase and of the last finished phase of
//! each direction (`Traces`). When a phase begins from the same turning state as the last
//! phase of its direction (the load to 1e−9 of ηP, stick ends, a and c to 1e−8 a), each of
//! its steps is started from that phase's step at the same load ([`Recalled`]). In a steady
//! cycle that step solves the new one to the tolerance in one residual evaluation. Otherwise
//! its residual exceeds the recall limit, and the step is solved as above
//! (`SlipOptions::recall`).
//!
//! A step's checks, φ0 and increments are functions of its two states (and the anchor, for
//! δ). When a step begins from a state whose geometry and slip signs are to the bit those of
//! the state the recalled step began from, and is accepted at the recalled geometry (its first
//! evaluation solved it), its two states are the recalled step's to the solver's tolerance:
//! it takes that step's checks and φ0 ([`Recalled::admissibility`]) and, when δ is followed
//! at the same anchor, its increments ([`SolvedStep::known_increments`]) instead of
//! evaluating them (test
//! `repeated_steps_take_the_checks_and_increments_they_would_compute`). In a steady cycle
//! every step does: the step is one residual evaluation.

use std::sync::{Arc, OnceLock};

use serde::{Deserialize, Serialize};

use crate::contact::memory::Memory;
use crate::contact::normal::NormalLoading;
use crate::contact::pressure::Discretisation;
use crate::contact::tangential::{
    PhaseStart, Recalled, SlipOptions, SlipStep, StepAdmissibility, WarmStart, solve_slip,
};
use crate::contact::{ContactModel, ContactState};
use crate::error::{Issue, SolveFailure};

/// Solver state of a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Regime {
    /// Monotonic normal loading (Spence's self-similar state).
    NormalLoading,
    /// Hold: ΔQ = 0, whole state unchanged.
    Stick,
    /// ΔQ > 0: both slip zones carry `q = +ηp`.
    ForwardSlip,
    /// ΔQ < 0: both slip zones carry `q = −ηp`.
    ReverseSlip,
}

impl Regime {
    /// `q/(ηp)` in the slip zones, `None` when nothing slips.
    pub fn slip_sign(self) -> Option<f64> {
        match self {
            Regime::ForwardSlip => Some(1.0),
            Regime::ReverseSlip => Some(-1.0),
            Regime::Stick | Regime::NormalLoading => None,
        }
    }
}

impl std::fmt::Display for Regime {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Regime::NormalLoading => "normal loading",
            Regime::Stick => "stick",
            Regime::ForwardSlip => "forward slip",
            Regime::ReverseSlip => "reverse slip",
        })
    }
}

/// The regime of a step with load increment `dq` (pure; `tol` absorbs round-off in ΔQ).
pub fn next_regime(dq: f64, tol: f64) -> Regime {
    if dq > tol {
        Regime::ForwardSlip
    } else if dq < -tol {
        Regime::ReverseSlip
    } else {
        Regime::Stick
    }
}

/// A piecewise-linear tangential load history in N/m.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LoadHistory {
    /// `(t, Q)` points, t strictly increasing (s, N/m).
    pub points: Vec<(f64, f64)>,
    /// Minimum number of steps per segment.
    pub steps_per_segment: usize,
    /// Largest |ΔQ| of a step (N/m).
    pub max_step: f64,
}

impl LoadHistory {
    /// A history from a lead-in and a cycle block repeated `repeats` times. Cycle times are
    /// relative to the start of each repetition (which is the end of the previous one).
    pub fn with_cycles(
        lead_in: &[(f64, f64)],
        cycle: &[(f64, f64)],
        repeats: usize,
    ) -> Vec<(f64, f64)> {
        let mut points = lead_in.to_vec();
        for _ in 0..repeats {
            let t0 = points.last().map_or(0.0, |p| p.0);
            points.extend(cycle.iter().map(|(t, q)| (t0 + t, *q)));
        }
        points
    }

    /// Check the history before any solving: finite values, strictly increasing times, and
    /// `|Q| < ηP` at every point (a point at or beyond ηP is gross sliding).
    pub fn validate(&self, path: &str, limit: f64) -> Vec<Issue> {
        let mut issues = Vec::new();
        if self.points.is_empty() {
            issues.push(Issue::new(
                format!("{path}.points"),
                "[] is invalid; it must hold at least one point",
            ));
        }
        for (i, &(t, q)) in self.points.iter().enumerate() {
            if !t.is_finite() {
                issues.push(Issue::new(
                    format!("{path}.points[{i}].t"),
                    format!("{t} s is invalid; it must be finite"),
                ));
            }
            if !q.is_finite() {
                issues.push(Issue::new(
                    format!("{path}.points[{i}].q"),
                    format!("{q} N/m is invalid; it must be finite"),
                ));
            } else if q.abs() >= limit {
                issues.push(Issue::new(
                    format!("{path}.points[{i}].q"),
                    format!(
                        "{q} N/m (= {:.4} ηP) is invalid; it must satisfy |Q| < ηP = {limit} N/m (at or beyond ηP the contact slides as a whole)",
                        q / limit
                    ),
                ));
            }
            if i > 0 {
                let prev = self.points[i - 1].0;
                if t.is_finite() && prev.is_finite() && t <= prev {
                    issues.push(Issue::new(
                        format!("{path}.points[{i}].t"),
                        format!("{t} s is invalid; it must be > previous t = {prev} s"),
                    ));
                }
            }
        }
        if self.steps_per_segment == 0 {
            issues.push(Issue::new(
                format!("{path}.steps_per_segment"),
                "0 is invalid; it must be ≥ 1",
            ));
        }
        if !(self.max_step.is_finite() && self.max_step > 0.0) {
            issues.push(Issue::new(
                format!("{path}.max_step"),
                format!(
                    "{} N/m is invalid; it must be finite and > 0",
                    self.max_step
                ),
            ));
        }
        issues
    }

    /// The number of steps of segment `k` (from point `k` to point `k + 1`):
    /// `max(steps_per_segment, ⌈|ΔQ|/max_step⌉)`, one for a hold.
    pub fn segment_steps(&self, k: usize) -> usize {
        let (q0, q1) = (self.points[k].1, self.points[k + 1].1);
        let n = self
            .steps_per_segment
            .max(((q1 - q0).abs() / self.max_step).ceil() as usize)
            .max(1);
        if (q1 - q0).abs() > 0.0 { n } else { 1 }
    }

    /// The load steps `(t, Q)` after the first point, each with its segment index.
    pub fn steps(&self) -> Vec<(usize, f64, f64)> {
        let mut out = Vec::new();
        for (k, w) in self.points.windows(2).enumerate() {
            let ((t0, q0), (t1, q1)) = (w[0], w[1]);
            let n = self.segment_steps(k);
            for i in 1..=n {
                let f = i as f64 / n as f64;
                out.push((k, t0 + f * (t1 - t0), q0 + f * (q1 - q0)));
            }
        }
        out
    }
}

/// One recorded step.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StepRecord {
    /// Step number (0 = end of normal loading).
    pub step: usize,
    /// Time (s).
    pub t: f64,
    /// Tangential load Q (N/m).
    pub q: f64,
    /// Regime.
    pub regime: Regime,
    /// Phase number (0 = normal loading; increments at each reversal).
    pub phase: usize,
    /// Contact half-width a (m).
    pub half_width: f64,
    /// Eccentricity e = −c (m).
    pub eccentricity: f64,
    /// Stick-zone left end (m).
    pub stick_lo: f64,
    /// Stick-zone right end (m).
    pub stick_hi: f64,
    /// `q/(ηp)` in the left slip zone (±1; 0 before any slip).
    pub left_slip_sign: f64,
    /// `q/(ηp)` in the right slip zone.
    pub right_slip_sign: f64,
    /// (Quasi-)Newton iterations on the step's geometry (stick ends, a, c) in the accepted
    /// attempt (`newton_iterations` in `steps.csv`).
    pub iterations: usize,
    /// Residual evaluations of the accepted attempt, each a coupled linear solve at fixed
    /// geometry, including those of finite-difference Jacobians (`evaluations` in `steps.csv`).
    pub newton_iterations: usize,
    /// Final relative change of the block iteration.
    pub residual: f64,
    /// Checks.
    pub admissibility: StepAdmissibility,
    /// Tangential displacement δ of the punch relative to the half-plane's datum (m), zero at
    /// the end of normal loading.
    pub displacement: f64,
    /// Energy dissipated by friction in this step (J/m), `−∫ q Δs dx` with the mid-step q.
    pub dissipation: f64,
    /// Work of the normal load in this step, `P Δδn` (J/m).
    pub normal_work: f64,
    /// Work of the electric load in this step, `φ̄0 ΔΓ` (J/m; zero under charge control).
    pub electric_work: f64,
}

/// Receives the accepted steps (progress bars, writers, test recorders).
pub trait Observer {
    /// Called once per accepted step with the committed state.
    fn on_step(&mut self, _record: &StepRecord, _state: &ContactState) {}
    /// Called when a new phase begins, with the memory that the phase will keep.
    fn on_phase(&mut self, _phase: usize, _memory: &Memory) {}
}

/// An observer that does nothing.
pub struct NoObserver;
impl Observer for NoObserver {}

/// A failed step, with its context.
#[derive(Debug, Clone)]
pub struct StepFailure {
    /// Step number.
    pub step: usize,
    /// Time.
    pub t: f64,
    /// Q.
    pub q: f64,
    /// Regime attempted.
    pub regime: Regime,
    /// The failure.
    pub failure: SolveFailure,
}

impl std::fmt::Display for StepFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "step {} (t = {} s, Q = {} N/m, {})",
            self.step, self.t, self.q, self.regime
        )
    }
}

/// Driver state that outlives a step.
#[derive(Debug, Clone)]
pub struct DriverState {
    /// Committed contact state.
    pub state: ContactState,
    /// Memory of the current phase.
    pub memory: Memory,
    /// Slip sign of the current phase (`None` before the first slip).
    pub phase_sign: Option<f64>,
    /// Phase number.
    pub phase: usize,
    /// `[Q, lo, hi, a, c]` of the last steps of the phase (at most [`HISTORY_POINTS`]), for the
    /// predictor of the next step.
    history: Vec<[f64; 5]>,
    /// Stick zone (with its correction chain) of the state that began the phase.
    base: Option<Arc<crate::contact::StickZone>>,
    /// Tangential load at the start of the phase (N/m).
    phase_start_load: f64,
    /// Accumulated punch displacement δ (m).
    pub displacement: f64,
    /// The material point at which δ is followed while it sticks (m).
    anchor: f64,
    /// `ux` of the committed state at the anchor, once computed: `(anchor, ux)` (m).
    anchor_ux: Option<(f64, f64)>,
    /// Normal approach δn of the current state (m), once computed.
    approach: Option<f64>,
    /// Slip signs and Jacobian of the last step, the warm start of the next step of a phase.
    warm: Option<WarmStart>,
    /// `dc/dQ` over the first step of the current phase: the start of the next phase's
    /// prediction of the contact centre.
    first_centre_slope: Option<f64>,
    /// The steps of the current phase, and of the last finished phase of each direction
    /// (reverse, forward): a later phase that begins from the same turning state recalls them.
    traces: Traces,
    /// How the last phase that began with mixed slip signs began ([`PhaseStart`]).
    last_start: Option<PhaseStart>,
}

/// The accepted steps of one phase ([`Recalled`]).
#[derive(Debug, Clone)]
struct PhaseTrace {
    /// `[Q, lo, hi, a, c]` of the state the phase began from.
    start: [f64; 5],
    /// Slip sign of the phase.
    sign: f64,
    /// The accepted steps.
    steps: Vec<TraceStep>,
}

/// An accepted step of a phase, kept for recall.
#[derive(Debug, Clone)]
struct TraceStep {
    /// The step's load (N/m).
    q: f64,
    /// Its state, slip signs and Jacobian.
    recalled: Recalled,
    /// Its increments, for a later step that reproduces it.
    increments: TracedIncrements,
}

/// A traced step's increments, for a later step that repeats it: they are a function of the
/// two states and the anchor.
#[derive(Debug, Clone)]
struct TracedIncrements {
    /// [`Footprint`] of the state the step began from.
    from: Footprint,
    /// The increments and the anchor they were taken at, set when the step is finished
    /// ([`finish_step`]).
    value: Arc<OnceLock<(f64, StepIncrements)>>,
}

impl TracedIncrements {
    /// Whether the traced step began from a state of footprint `from`.
    fn began_from(&self, from: Footprint) -> bool {
        self.from == from
    }

    /// The increments, for a step that repeated the traced one (`SlipStep::repeated`, which
    /// the solver grants only to a step that began where the traced one began) with δ
    /// followed at `anchor`, once they are known.
    fn for_repeat(&self, anchor: f64) -> Option<StepIncrements> {
        let (taken_at, increments) = self.value.get()?;
        (taken_at.to_bits() == anchor.to_bits()).then_some(*increments)
    }
}

/// The bits of a state's stick ends, contact half-width and centre, and slip signs: a state
/// that began a traced step and the state a later step begins from are the same state when
/// their footprints are equal (the later one a repeat of the earlier, accepted at its geometry
/// without iterating).
type Footprint = [u64; 6];

fn footprint(state: &ContactState) -> Footprint {
    let [_, lo, hi, a, c] = load_and_geometry(state);
    let signs = [state.traction.left_sign, state.traction.right_sign];
    let mut out = [0; 6];
    for (o, v) in out.iter_mut().zip([lo, hi, a, c].into_iter().chain(signs)) {
        *o = v.to_bits();
    }
    out
}

/// The current phase's trace and the last finished one of each direction.
#[derive(Debug, Clone, Default)]
struct Traces {
    current: Option<PhaseTrace>,
    /// Reverse (index 0) and forward (index 1).
    finished: [Option<PhaseTrace>; 2],
}

impl Traces {
    /// The step at load `q` of the last finished phase with slip sign `sign` that began from
    /// the turning state `start` (`[Q, lo, hi, a, c]`), when there is one. Loads and
    /// geometries match to 1e−9 of ηP and 1e−8 of a: a steady cycle repeats its steps to
    /// about the solver's tolerance, and the recalled state must solve the step anyway.
    fn recall(&self, start: &[f64; 5], sign: f64, q: f64, limit: f64) -> Option<&TraceStep> {
        let trace = self.finished[usize::from(sign > 0.0)].as_ref()?;
        let a = start[3];
        let same_start = (trace.start[0] - start[0]).abs() <= 1e-9 * limit
            && (1..5).all(|k| (trace.start[k] - start[k]).abs() <= 1e-8 * a);
        if !same_start {
            return None;
        }
        trace.steps.iter().find(|s| (s.q - q).abs() <= 1e-9 * limit)
    }

    /// Record an accepted step (`None`: one that is not to be recalled); `start` begins a new
    /// phase (`[Q, lo, hi, a, c]` of its turning state), and the current trace is then
    /// finished.
    fn push(&mut self, start: Option<[f64; 5]>, sign: f64, step: Option<TraceStep>) {
        if let Some(start) = start {
            if let Some(done) = self.current.take() {
                let slot = usize::from(done.sign > 0.0);
                self.finished[slot] = Some(done);
            }
            self.current = Some(PhaseTrace {
                start,
                sign,
                steps: Vec::new(),
            });
        }
        if let (Some(trace), Some(step)) = (self.current.as_mut(), step) {
            trace.steps.push(step);
        }
    }
}

/// `[Q, lo, hi, a, c]` of a state (its stick zone, or the whole contact when none).
fn load_and_geometry(state: &ContactState) -> [f64; 5] {
    let (c, a) = (state.centre, state.half_width);
    let (lo, hi) = state
        .traction
        .stick
        .as_ref()
        .map_or((c - a, c + a), |z| (z.lo, z.hi));
    [state.tangential_load, lo, hi, a, c]
}

impl DriverState {
    /// Start from the end of normal loading.
    pub fn after_normal_loading(normal: &NormalLoading) -> Self {
        let state = normal.state.clone();
        let b = normal.stick_half_width;
        let memory =
            Memory::after_normal_loading(Arc::new(state.clone()), normal.strain_slope, -b, b);
        let base = normal.state.traction.stick.clone().map(Arc::new);
        Self {
            state,
            memory,
            phase_sign: None,
            phase: 0,
            history: Vec::new(),
            base,
            phase_start_load: 0.0,
            displacement: 0.0,
            anchor: normal
                .state
                .traction
                .stick
                .as_ref()
                .map_or(0.0, |z| z.mid()),
            anchor_ux: None,
            approach: None,
            warm: None,
            first_centre_slope: None,
            traces: Traces::default(),
            last_start: None,
        }
    }
}

/// Initial guess of the stick zone at the first step of a phase with sign `sign` and
/// increment `dq` from `prev`.
fn phase_start_guess(model: &ContactModel, prev: &ContactState, sign: f64, dq: f64) -> (f64, f64) {
    let (c, a) = (prev.centre, prev.half_width);
    let width =
        a * (1.0 - (1.0 - (dq.abs() / (2.0 * model.friction * prev.normal_load)).min(0.9)).sqrt());
    let width = width.max(1e-6 * a);
    let t = &prev.traction;
    let (plo, phi) = t.stick.as_ref().map_or((c - a, c + a), |s| (s.lo, s.hi));
    // A slip zone already slipping in the new direction keeps slipping and its stick end moves
    // inward at once (start just inside it: outside, the residuals do not depend on that end);
    // elsewhere new slip zones open at the contact ends.
    let lo = if (t.left_sign - sign).abs() < 1e-12 {
        plo + width
    } else {
        c - a + width
    };
    let hi = if (t.right_sign - sign).abs() < 1e-12 {
        phi - width
    } else {
        c + a - width
    };
    (lo, hi)
}

/// A load point of the history: step number, time (s) and Q (N/m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoadPoint {
    /// Step number.
    pub step: usize,
    /// Time (s).
    pub t: f64,
    /// Tangential load (N/m).
    pub q: f64,
}

/// Advance the driver by one load step: solve it ([`solve_step`]), compute its increments
/// ([`StepIncrements::compute`]) and commit them ([`finish_step`]).
pub fn advance(
    model: &ContactModel,
    disc: &Discretisation,
    driver: &mut DriverState,
    point: LoadPoint,
    options: SlipOptions,
    observer: &mut dyn Observer,
) -> Result<StepRecord, StepFailure> {
    Ok(match solve_step(model, disc, driver, point, options)? {
        Solved::Hold(regime) => hold_record(driver, point, regime, observer),
        Solved::Slip(solved) => {
            let increments = solved.known_increments().unwrap_or_else(|| {
                StepIncrements::compute(model, &solved.increment_inputs(driver))
            });
            finish_step(driver, *solved, increments, observer)
        }
    })
}

/// A solved step: a hold (nothing changes) or a slip step whose increments are still to be
/// computed.
pub enum Solved {
    /// ΔQ = 0 (the regime is [`Regime::Stick`]).
    Hold(Regime),
    /// A slip step, committed to the driver except for its increments.
    Slip(Box<SolvedStep>),
}

/// A slip step whose state is committed to the driver and whose increments (δ, dissipation,
/// works) are still to be computed; they need only the two states and the anchor, so they
/// can be computed while the next step is solved.
pub struct SolvedStep {
    /// The step's record without the increments.
    record: StepRecord,
    /// The states and the anchor; what the previous step knows of the old state is filled in
    /// by [`SolvedStep::increment_inputs`].
    inputs: IncrementInputs,
    /// The phase this step begins, with its memory (for the observer).
    new_phase: Option<(usize, Memory)>,
    /// The increments, when the step reproduced a recalled step whose increments are known.
    known: Option<StepIncrements>,
    /// Where the step's increments are kept for a later phase that recalls it.
    trace: Option<Arc<OnceLock<(f64, StepIncrements)>>>,
}

/// What the increments of a step need.
#[derive(Clone)]
pub struct IncrementInputs {
    /// The committed state before the step.
    pub old: Arc<ContactState>,
    /// The state of the step.
    pub new: Arc<ContactState>,
    /// The material point at which δ is followed (m).
    pub anchor: f64,
    /// `ux` of the old state at the anchor, when the previous step computed it (m).
    pub old_ux: Option<f64>,
    /// The normal approach of the old state, when already computed (m).
    pub old_approach: Option<f64>,
}

/// The increments of a step and the values at its state that the next step reuses.
#[derive(Debug, Clone, Copy)]
pub struct StepIncrements {
    /// Δδ (m).
    pub displacement: f64,
    /// Frictional dissipation (J/m).
    pub dissipation: f64,
    /// Work of P, `P Δδn` (J/m).
    pub normal_work: f64,
    /// Work of the electric load, `φ̄0 ΔΓ` (J/m).
    pub electric_work: f64,
    /// `ux` of the new state at the anchor (m).
    pub new_ux: f64,
    /// Normal approach δn of the new state (m).
    pub new_approach: f64,
}

impl StepIncrements {
    /// The increments between `inputs.old` and `inputs.new`.
    ///
    /// The punch moves rigidly, so on the new stick zone `Δux` is uniform and equals `Δδ`; it
    /// is taken at the material point `anchor` of the stick zone. The driver keeps one anchor
    /// for as long as it sticks, so that the increments telescope: δ is then `ux(anchor)` of
    /// the current state plus a constant, and a cycle that repeats its states repeats δ
    /// exactly (averaging over points that change from step to step leaves the
    /// discretisation error of `ux` to accumulate as a drift, measured at 2e−6 of the loop's δ
    /// range per cycle for the Figure-4 history). `ux(anchor)` and δn come from one pass over
    /// each state ([`ContactState::displacement_and_approach`]); the old state's are taken
    /// from `inputs` when the previous step computed them. The dissipation is
    /// [`step_dissipation`]'s.
    pub fn compute(model: &ContactModel, inputs: &IncrementInputs) -> Self {
        let (old, new) = (&inputs.old, &inputs.new);
        let (new_ux, new_approach) = new.displacement_and_approach(model, inputs.anchor);
        let (old_ux, old_approach) = match (inputs.old_ux, inputs.old_approach) {
            (Some(ux), Some(approach)) => (ux, approach),
            (ux, approach) => {
                let (u, n) = old.displacement_and_approach(model, inputs.anchor);
                (ux.unwrap_or(u), approach.unwrap_or(n))
            }
        };
        let (displacement, dissipation) = match new.traction.stick {
            Some(_) => (new_ux - old_ux, step_dissipation(model, old, new)),
            None => (0.0, 0.0),
        };
        let electric_work = match (old.potential, new.potential) {
            (Some(a), Some(b)) => 0.5 * (a + b) * (new.charge - old.charge),
            _ => 0.0,
        };
        Self {
            displacement,
            dissipation,
            normal_work: new.normal_load * (new_approach - old_approach),
            electric_work,
            new_ux,
            new_approach,
        }
    }
}

impl SolvedStep {
    /// The increments, when they are known without computing them: the step reproduced a
    /// recalled step (the same geometry and slip signs to the bit) that began from the state
    /// this one began from, and δ is followed at the same anchor. They are then the recalled
    /// step's, which were computed from the same two states.
    pub fn known_increments(&self) -> Option<StepIncrements> {
        self.known
    }

    /// The inputs of this step's increments, with what the driver already knows of the old
    /// state (call after the previous step is finished).
    pub fn increment_inputs(&self, driver: &DriverState) -> IncrementInputs {
        let anchor = self.inputs.anchor;
        IncrementInputs {
            old_ux: driver
                .anchor_ux
                .filter(|(x, _)| x.to_bits() == anchor.to_bits())
                .map(|(_, u)| u),
            old_approach: driver.approach,
            ..self.inputs.clone()
        }
    }
}

/// The record of a hold step (nothing changes), passed to the observer.
fn hold_record(
    driver: &DriverState,
    point: LoadPoint,
    regime: Regime,
    observer: &mut dyn Observer,
) -> StepRecord {
    let mut rec = record(point.step, point.t, driver, regime, None);
    rec.q = point.q;
    observer.on_step(&rec, &driver.state);
    rec
}

/// Commit a solved step's increments to the driver (δ, the anchor's ux, δn) and pass its
/// record to the observer (after the phase it begins, if any). Steps must be finished in
/// order.
pub fn finish_step(
    driver: &mut DriverState,
    solved: SolvedStep,
    increments: StepIncrements,
    observer: &mut dyn Observer,
) -> StepRecord {
    if let Some(cell) = &solved.trace {
        // Set once: a step is finished once.
        let _ = cell.set((solved.inputs.anchor, increments));
    }
    driver.anchor_ux = Some((solved.inputs.anchor, increments.new_ux));
    driver.approach = Some(increments.new_approach);
    driver.displacement += increments.displacement;
    let mut rec = solved.record;
    rec.displacement = driver.displacement;
    rec.dissipation = increments.dissipation;
    rec.normal_work = increments.normal_work;
    rec.electric_work = increments.electric_work;
    if let Some((phase, memory)) = &solved.new_phase {
        observer.on_phase(*phase, memory);
    }
    observer.on_step(&rec, &solved.inputs.new);
    rec
}

/// Steps of the current phase kept for the predictor of the next step ([`predict`]).
const HISTORY_POINTS: usize = 3;

/// The geometry `(lo, hi, a, c)` of a step at load q, extrapolated from the steps of the
/// phase so far (`[Q, lo, hi, a, c]`, oldest first): by the polynomial in Q through the last
/// three (quadratic), two (linear) or one (constant). `None` before the phase's first step.
///
/// The geometry is smooth in Q within a phase, so the quadratic predictor starts the step
/// closer to its solution than the linear one of the stick ends alone with the previous
/// (a, c), which saves residual evaluations.
fn predict(history: &[[f64; 5]], q: f64) -> Option<[f64; 4]> {
    let last = history.last()?;
    // Points with distinct loads only (a repeated load would make the polynomial singular).
    let mut points: Vec<&[f64; 5]> = vec![last];
    for p in history.iter().rev().skip(1) {
        if points
            .iter()
            .all(|o| (o[0] - p[0]).abs() > 1e-12 * o[0].abs().max(p[0].abs()))
        {
            points.push(p);
        }
    }
    let mut out = [0.0; 4];
    for (j, v) in out.iter_mut().enumerate() {
        // Lagrange's form through the points.
        *v = points
            .iter()
            .enumerate()
            .map(|(i, pi)| {
                let weight: f64 = points
                    .iter()
                    .enumerate()
                    .filter(|&(k, _)| k != i)
                    .map(|(_, pk)| (q - pk[0]) / (pi[0] - pk[0]))
                    .product();
                weight * pi[j + 1]
            })
            .sum();
    }
    Some(out)
}

/// Solve one load step and commit its state to the driver (phase, memory, anchor, warm
/// start); its increments are left to [`finish_step`].
pub fn solve_step(
    model: &ContactModel,
    disc: &Discretisation,
    driver: &mut DriverState,
    point: LoadPoint,
    options: SlipOptions,
) -> Result<Solved, StepFailure> {
    let LoadPoint { step, t, q } = point;
    let dq = q - driver.state.tangential_load;
    let limit = model.friction * driver.state.normal_load;
    let regime = next_regime(dq, 1e-12 * limit);
    let Some(sign) = regime.slip_sign() else {
        return Ok(Solved::Hold(regime));
    };
    let new_phase = driver.phase_sign != Some(sign);
    let predicted = (!new_phase).then(|| predict(&driver.history, q)).flatten();
    let guess = if new_phase {
        phase_start_guess(model, &driver.state, sign, dq)
    } else {
        match predicted {
            Some([lo, hi, ..]) => (lo, hi),
            None => phase_start_guess(model, &driver.state, sign, dq),
        }
    };
    if new_phase && let Some(zone) = driver.state.traction.stick.as_ref() {
        // The turning state is about to be cloned into the memory and into the new phase's
        // base, and both are evaluated at every residual evaluation of the phase: tabulate its
        // H'q̃ and q̃ first, so that the clones share one table (`StickZone::tabulate`; the
        // normal-loading state comes tabulated, and earlier bases in the chain were tabulated
        // when their phases began). A zone accepted in the middle of a phase is evaluated only
        // by the next step's checks and increments, too few times to pay for a table (default
        // run: tabulating every accepted zone 1.81 s, the bases only 1.60 s, δ and the stick
        // ends the same to 1e−13 of themselves).
        zone.tabulate(disc.nodes() + 32);
    }
    let memory = if new_phase {
        match (&driver.phase_sign, driver.state.traction.stick.as_ref()) {
            (None, _) => driver.memory.clone(),
            (Some(_), Some(s)) => {
                driver
                    .memory
                    .committed(Arc::new(driver.state.clone()), s.lo, s.hi)
            }
            (Some(_), None) => driver.memory.clone(),
        }
    } else {
        driver.memory.clone()
    };
    let base = if new_phase {
        driver.state.traction.stick.clone().map(Arc::new)
    } else {
        driver.base.clone()
    };
    // Second guess: the Mindlin–Deresiewicz size for the load change since the phase began,
    // centred on the contact.
    let start_load = if new_phase {
        driver.state.tangential_load
    } else {
        driver.phase_start_load
    };
    let (c, a) = (driver.state.centre, driver.state.half_width);
    let md = (1.0 - ((q - start_load).abs() / (2.0 * limit)).min(0.95)).sqrt();
    let md_guess = (c - a * md, c + a * md);
    // After a step with mixed slip signs (the first steps after a reversal, one edge still
    // slipping the old way) the previous stick ends do not continue the standard state: its
    // edge zone closes and that stick end jumps. The continuation then converges to a state
    // that fails the stick check (about 20 wasted evaluations at each such step), so the
    // Mindlin–Deresiewicz guess goes first; the states are the same either way.
    let after_mixed = driver.warm.is_some_and(|w| w.signs != (sign, sign));
    let guesses = if after_mixed {
        [md_guess, guess]
    } else {
        [guess, md_guess]
    };
    // The contact's half-width and centre to start from: extrapolated within a phase. At a
    // phase start the centre is moved by dc/dQ of the previous phase's first step times ΔQ,
    // and the half-width, which changes little, is kept. (The first step of a reversal moves
    // the centre by about as much as the first loading step did; started from the old centre,
    // the mixed-sign attempt of a reversal step spends about ten quasi-Newton iterations
    // getting there. The states are the same either way.)
    let contact = if new_phase {
        driver.first_centre_slope.map(|slope| (a, c + slope * dq))
    } else {
        predicted.map(|[.., a, c]| (a, c))
    };
    // The same step of the last phase in this direction that began from the same turning
    // state: in a steady cycle it solves this step again.
    let phase_start = if new_phase {
        Some(load_and_geometry(&driver.state))
    } else {
        driver.traces.current.as_ref().map(|t| t.start)
    };
    let traced = phase_start
        .filter(|_| options.recall)
        .and_then(|start| driver.traces.recall(&start, sign, q, limit))
        .cloned();
    // The recalled step's checks go with it when this step begins from its start.
    let from = footprint(&driver.state);
    let recalled = traced.as_ref().map(|t| Recalled {
        admissibility: t
            .recalled
            .admissibility
            .filter(|_| t.increments.began_from(from)),
        ..t.recalled.clone()
    });
    let solved: SlipStep = solve_slip(
        model,
        disc,
        &memory,
        base.as_ref(),
        &driver.state,
        q,
        sign,
        &guesses,
        contact,
        if new_phase {
            None
        } else {
            driver.warm.as_ref()
        },
        recalled.as_ref(),
        driver.last_start.as_ref().filter(|_| new_phase),
        options,
    )
    .map_err(|failure| StepFailure {
        step,
        t,
        q,
        regime,
        failure,
    })?;
    if new_phase {
        if let Some(start) = PhaseStart::of(&solved.state, sign) {
            driver.last_start = Some(start);
        }
        driver.first_centre_slope = Some((solved.state.centre - c) / dq);
        driver.phase += 1;
        driver.phase_start_load = start_load;
        driver.phase_sign = Some(sign);
        driver.memory = memory;
        driver.base = base;
        driver.history.clear();
    }
    // Keep the anchor of δ while it sticks; otherwise take the middle of the part of the old
    // stick zone that still sticks.
    let new_zone = solved.state.traction.stick.as_ref().expect("slip state");
    let margin = 1e-3 * (new_zone.hi - new_zone.lo);
    if !(driver.anchor > new_zone.lo + margin && driver.anchor < new_zone.hi - margin) {
        let (lo, hi) = driver
            .state
            .traction
            .stick
            .as_ref()
            .map_or((new_zone.lo, new_zone.hi), |z| {
                (z.lo.max(new_zone.lo), z.hi.min(new_zone.hi))
            });
        driver.anchor = if hi > lo {
            0.5 * (lo + hi)
        } else {
            new_zone.mid()
        };
    }
    driver.warm = Some(WarmStart {
        signs: (
            solved.state.traction.left_sign,
            solved.state.traction.right_sign,
        ),
        jacobian: solved.jacobian,
    });
    // A step that repeated the recalled one, with the same anchor, has its increments
    // (module docs, "Recall of a repeated phase").
    let known = traced
        .filter(|_| solved.repeated)
        .and_then(|t| t.increments.for_repeat(driver.anchor));
    let old = std::mem::replace(&mut driver.state, solved.state.clone());
    driver.history.push(load_and_geometry(&driver.state));
    if driver.history.len() > HISTORY_POINTS {
        driver.history.remove(0);
    }
    let record = record(step, t, driver, regime, Some(&solved));
    let new = Arc::new(solved.state);
    // A step accepted at a stalled residual is not recalled: the next cycle's step tries to
    // converge (default history at M = 64 with 20 steps per segment: the step at −0.075 ηP
    // stalled at 1.4e−6 in the second cycle and converged from its own path in the third).
    let converged = solved.residual < options.tolerance;
    let increments = Arc::new(OnceLock::new());
    let trace = converged.then(|| TraceStep {
        q,
        recalled: Recalled {
            state: Arc::clone(&new),
            warm: driver.warm.expect("set above"),
            admissibility: Some(solved.admissibility),
        },
        increments: TracedIncrements {
            from,
            value: Arc::clone(&increments),
        },
    });
    driver
        .traces
        .push(phase_start.filter(|_| new_phase), sign, trace);
    Ok(Solved::Slip(Box::new(SolvedStep {
        record,
        inputs: IncrementInputs {
            old: Arc::new(old),
            new,
            anchor: driver.anchor,
            old_ux: None,
            old_approach: None,
        },
        new_phase: new_phase.then(|| (driver.phase, driver.memory.clone())),
        known,
        trace: converged.then_some(increments),
    })))
}

/// The record of the driver's committed state, with zero increments (a hold's; a slip step's
/// are filled in by [`finish_step`]).
fn record(
    step: usize,
    t: f64,
    driver: &DriverState,
    regime: Regime,
    solved: Option<&SlipStep>,
) -> StepRecord {
    let s = &driver.state;
    let (lo, hi) = s
        .traction
        .stick
        .as_ref()
        .map_or((s.centre - s.half_width, s.centre + s.half_width), |z| {
            (z.lo, z.hi)
        });
    StepRecord {
        step,
        t,
        q: s.tangential_load,
        regime,
        phase: driver.phase,
        half_width: s.half_width,
        eccentricity: -s.centre,
        stick_lo: lo,
        stick_hi: hi,
        left_slip_sign: s.traction.left_sign,
        right_slip_sign: s.traction.right_sign,
        iterations: solved.map_or(0, |x| x.iterations),
        newton_iterations: solved.map_or(0, |x| x.newton_iterations),
        residual: solved.map_or(0.0, |x| x.residual),
        admissibility: solved.map_or_else(StepAdmissibility::default, |x| x.admissibility),
        displacement: driver.displacement,
        dissipation: 0.0,
        normal_work: 0.0,
        electric_work: 0.0,
    }
}

/// The frictional dissipation between two states (zero when the new state has no stick zone).
///
/// In a slip zone the slip increment is `Δs(x) = ∫ from the stick end to x of Δε` (Δε the
/// change of the surface strain), and the dissipated energy `−∫ q̄ Δs dx` (q̄ the mean of the
/// two tractions, second order in the step) is evaluated after an integration by parts as
/// `∓∫ Δε(t) T(t) dt`, with T the integral of q̄ from t to the contact end, so that Δε is
/// needed only at the quadrature nodes.
pub fn step_dissipation(model: &ContactModel, old: &ContactState, new: &ContactState) -> f64 {
    let m = new.pressure.beta.len();
    let rule = (
        crate::contact::slip_zone_rule_nodes(m),
        Some(crate::contact::slip_zone_smooth_nodes(m)),
    );
    step_dissipation_with(model, old, new, rule)
}

/// [`step_dissipation`] by the graded rule with `nodes` per piece, and `smooth` nodes of the
/// plain rule on the pieces both of whose ends the balancing made (none: the graded rule on
/// every piece; [`crate::contact::graded_cumulative`]).
fn step_dissipation_with(
    model: &ContactModel,
    old: &ContactState,
    new: &ContactState,
    (nodes, smooth): (usize, Option<usize>),
) -> f64 {
    let Some(stick) = new.traction.stick.as_ref() else {
        return 0.0;
    };
    // q̄ onto `out` and Δε onto `changes` at each of xs, each state's pressure computed once
    // for its traction and strain.
    let mean_and_change = |xs: &[f64], out: &mut Vec<f64>, changes: &mut Vec<f64>| {
        let fields = |state: &ContactState| {
            let (mut p, mut h, mut q, mut strain) =
                (Vec::new(), Vec::new(), Vec::new(), Vec::new());
            state.pressures_and_cauchys_into(xs, &mut p, &mut h);
            state.tractions_with(xs, &p, &mut q);
            state.strains_with(model, xs, (&p, &h), &mut strain);
            (q, strain)
        };
        let ((q_new, strain_new), (q_old, strain_old)) = (fields(new), fields(old));
        out.extend(q_new.iter().zip(&q_old).map(|(n, o)| 0.5 * (o + n)));
        changes.extend(strain_new.iter().zip(&strain_old).map(|(n, o)| n - o));
    };
    let left_end = (old.centre - old.half_width).min(new.centre - new.half_width);
    let right_end = (old.centre + old.half_width).max(new.centre + new.half_width);
    // Measured on the default history: without the contact ends among the breakpoints the
    // step dissipation differs from the one with them by up to 1e−4 of itself (3e−2 at the
    // first steps after a reversal, where it is small); with them, and with the pieces
    // balanced (`graded_cumulative` halves a piece that is more than three times as long as
    // a neighbour, so that no singular point sits just outside a long piece), the rule of
    // `slip_zone_rule_nodes` agrees with four times its nodes to 5e−9 at every step,
    // M = 64 … 512. The pieces that the balancing made at both ends take the plain rule of
    // `slip_zone_smooth_nodes` (half the nodes: test
    // `the_dissipation_rule_gives_the_step_dissipations_to_a_small_error`).
    // (Unbalanced, one step, 0.048a of slip zone next to a 0.003a piece, was off by 4e−4 of
    // itself even with 96 nodes.)
    let breaks = crate::contact::step_breakpoints(old, new);
    // q̄ and Δε on the graded nodes of each slip zone, split at the traction's breakpoints,
    // with the running integral of q̄ for the inner integral.
    let table = |from: f64, to: f64| {
        let mut pts: Vec<f64> = breaks
            .iter()
            .copied()
            .filter(|x| *x > from && *x < to)
            .collect();
        pts.extend([from, to]);
        let mut changes = Vec::new();
        let table = crate::contact::graded_cumulative(pts, nodes, smooth, &mut |xs, out| {
            mean_and_change(xs, out, &mut changes)
        });
        (table, changes)
    };
    // Right zone: −∫_{hi}^{R} Δε(t) ∫_t^R q̄; left zone: +∫_{L}^{lo} Δε(t) ∫_L^t q̄.
    let (right_table, right_changes) = table(stick.hi, right_end);
    let right: f64 = right_table
        .nodes
        .iter()
        .zip(right_changes)
        .map(|(&(_, w, _, before), d)| w * d * (right_table.total - before))
        .sum();
    let (left_table, left_changes) = table(left_end, stick.lo);
    let left: f64 = left_table
        .nodes
        .iter()
        .zip(left_changes)
        .map(|(&(_, w, _, before), d)| w * d * before)
        .sum();
    -right + left
}

/// A finished run: the records and the final driver state.
#[derive(Debug, Clone)]
pub struct HistoryRun {
    /// One record per accepted step (step 0 = end of normal loading).
    pub records: Vec<StepRecord>,
    /// The driver after the last step.
    pub driver: DriverState,
}

/// A failed run: what was accepted before the failure, and the failure.
#[derive(Debug, Clone)]
pub struct HistoryFailure {
    /// The steps accepted before the failure.
    pub records: Vec<StepRecord>,
    /// The driver at the last accepted step.
    pub driver: DriverState,
    /// The failed step.
    pub failure: StepFailure,
}

/// Walk a whole history from the end of normal loading.
pub fn run_history(
    model: &ContactModel,
    disc: &Discretisation,
    normal: &NormalLoading,
    history: &LoadHistory,
    options: SlipOptions,
    observer: &mut dyn Observer,
) -> Result<HistoryRun, Box<HistoryFailure>> {
    let mut driver = DriverState::after_normal_loading(normal);
    let t0 = history.points.first().map_or(0.0, |p| p.0);
    let mut records = vec![record(0, t0, &driver, Regime::NormalLoading, None)];
    observer.on_step(&records[0], &driver.state);
    let q0 = history.points.first().map_or(0.0, |p| p.1);
    let mut steps = Vec::new();
    if q0.abs() > 0.0 {
        // Ramp from Q = 0 to the first point in one segment's worth of steps.
        let n = history
            .steps_per_segment
            .max((q0.abs() / history.max_step).ceil() as usize);
        for i in 1..=n {
            steps.push((t0, q0 * i as f64 / n as f64));
        }
    }
    steps.extend(history.steps().into_iter().map(|(_, t, q)| (t, q)));
    let points: Vec<LoadPoint> = steps
        .into_iter()
        .enumerate()
        .map(|(i, (t, q))| LoadPoint { step: i + 1, t, q })
        .collect();
    let failure = continue_run(
        model,
        disc,
        &mut driver,
        &points,
        options,
        observer,
        &mut records,
    );
    match failure {
        None => Ok(HistoryRun { records, driver }),
        Some(failure) => Err(Box::new(HistoryFailure {
            records,
            driver,
            failure,
        })),
    }
}

/// Walk the load points `points` from `driver` as [`run_history`] does, pushing a record per
/// step onto `records` (the observer sees each), and return the first failure, if any (the
/// driver is then at the last accepted step).
///
/// Pipelined on two threads: a step's increments (δ, dissipation, δn: a third of the work of
/// a step) need only its two states, so they are computed on a worker thread while the next
/// step is solved; steps are finished in order, so records, δ and the observer's calls are
/// those of the sequential [`advance`]. One worker for the run (a thread spawned per step
/// cost its stack mappings and wake-ups at every step). A step whose increments are known (a
/// recalled step, [`SolvedStep::known_increments`]) sends the worker nothing.
pub fn continue_run(
    model: &ContactModel,
    disc: &Discretisation,
    driver: &mut DriverState,
    points: &[LoadPoint],
    options: SlipOptions,
    observer: &mut dyn Observer,
    records: &mut Vec<StepRecord>,
) -> Option<StepFailure> {
    std::thread::scope(|scope| {
        let (jobs, inbox) = std::sync::mpsc::channel::<IncrementInputs>();
        let (outbox, results) = std::sync::mpsc::channel();
        scope.spawn(move || {
            for inputs in inbox {
                if outbox
                    .send(StepIncrements::compute(model, &inputs))
                    .is_err()
                {
                    break;
                }
            }
        });
        let finish = |pending: Option<Box<SolvedStep>>,
                      driver: &mut DriverState,
                      records: &mut Vec<StepRecord>,
                      observer: &mut dyn Observer| {
            if let Some(solved) = pending {
                let increments = solved.known_increments().unwrap_or_else(|| {
                    results
                        .recv()
                        .expect("the increments of a step do not panic")
                });
                records.push(finish_step(driver, *solved, increments, observer));
            }
        };
        let mut pending: Option<Box<SolvedStep>> = None;
        for &point in points {
            let solved = solve_step(model, disc, driver, point, options);
            finish(pending.take(), driver, records, observer);
            match solved {
                Ok(Solved::Hold(regime)) => {
                    records.push(hold_record(driver, point, regime, observer));
                }
                Ok(Solved::Slip(solved)) => {
                    if solved.known_increments().is_none() {
                        jobs.send(solved.increment_inputs(driver))
                            .expect("the increments worker runs until the steps end");
                    }
                    pending = Some(solved);
                }
                Err(failure) => return Some(failure),
            }
        }
        finish(pending.take(), driver, records, observer);
        None
    })
}

/// The driver at the end of the normal loading of scenario `sc` on `disc` (tests' start).
#[cfg(test)]
pub(crate) fn driver_after_normal_loading(
    sc: &crate::scenario::Scenario,
    disc: &Discretisation,
) -> DriverState {
    use crate::contact::normal::{NormalOptions, solve_normal};
    let normal = solve_normal(&sc.model, disc, sc.normal_load, NormalOptions::default()).unwrap();
    DriverState::after_normal_loading(&normal)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The dissipation's rule (the graded rule, and the plain rule on the pieces that the
    /// balancing made at both ends, `slip_zone_smooth_nodes`) gives the step dissipations as
    /// four times the graded rule on every piece does, to a small fraction of the largest, over
    /// the first two phases of the default history at M = 128.
    #[test]
    fn the_dissipation_rule_gives_the_step_dissipations_to_a_small_error() {
        let sc = crate::scenario::default_scenario();
        let disc = Discretisation::new(128);
        let mut driver = driver_after_normal_loading(&sc, &disc);
        let steps = sc.history.as_ref().expect("default history").steps();
        let fine = (4 * crate::contact::slip_zone_rule_nodes(128), None);
        let graded = crate::contact::slip_zone_rule_nodes(128);
        let (mut rule, mut reference, mut few) = (Vec::new(), Vec::new(), Vec::new());
        for (i, &(_, t, q)) in steps.iter().take(30).enumerate() {
            let old = driver.state.clone();
            let point = LoadPoint { step: i + 1, t, q };
            let options = SlipOptions::default();
            advance(
                &sc.model,
                &disc,
                &mut driver,
                point,
                options,
                &mut NoObserver,
            )
            .unwrap();
            rule.push(step_dissipation(&sc.model, &old, &driver.state));
            reference.push(step_dissipation_with(&sc.model, &old, &driver.state, fine));
            few.push(step_dissipation_with(
                &sc.model,
                &old,
                &driver.state,
                (graded, Some(4)),
            ));
        }
        let largest = reference.iter().fold(0.0f64, |m, d| m.max(d.abs()));
        let worst_of = |rule: &[f64]| {
            rule.iter()
                .zip(&reference)
                .fold(0.0f64, |m, (r, e)| m.max((r - e).abs()))
                / largest
        };
        let (worst, with_four) = (worst_of(&rule), worst_of(&few));
        println!("step dissipations within {worst:.2e} of the largest ({with_four:.2e} with 4)");
        // The smooth pieces are there and carry weight: 4 plain nodes on them are too few.
        assert!(with_four > 1e-6, "{with_four:e}");
        // Measured 1.5e−14, as with the graded rule's 32 nodes on every piece (8 plain nodes
        // on the smooth pieces: 1.6e−7; 4: 4.7e−6). The dissipation's discretisation error at
        // M = 128 is 4.1e−5 of a cycle's friction work (`docs/performance.md`).
        assert!(worst > 0.0 && worst < 1e-12, "{worst:e}");
    }

    /// A traced step's increments go to a later step only when it begins from the state the
    /// traced step began from (footprints equal to the bit; that it then repeated the traced
    /// step, at its geometry to the bit, is the solver's `repeated`, tested in the tangential
    /// module) and follows δ at the same anchor, and only once they are known.
    #[test]
    fn traced_increments_need_the_start_and_the_anchor() {
        let increments = StepIncrements {
            displacement: 1e-9,
            dissipation: 2e-9,
            normal_work: 3e-9,
            electric_work: 0.0,
            new_ux: 4e-9,
            new_approach: 5e-9,
        };
        let (from, anchor) = ([1, 2, 3, 4, 5, 6], 1e-6);
        let traced = TracedIncrements {
            from,
            value: Arc::new(OnceLock::new()),
        };
        assert!(traced.for_repeat(anchor).is_none(), "not yet finished");
        traced.value.set((anchor, increments)).unwrap();
        let got = traced.for_repeat(anchor).expect("the traced step's");
        assert_eq!(got.dissipation.to_bits(), increments.dissipation.to_bits());
        assert!(traced.began_from(from));
        for k in 0..6 {
            let mut other = from;
            other[k] += 1;
            assert!(!traced.began_from(other), "from, bit {k}");
        }
        let next = f64::from_bits(anchor.to_bits() + 1);
        assert!(traced.for_repeat(next).is_none(), "anchor");
    }

    /// The predictor is the polynomial through the phase's last steps: exact for a quadratic
    /// path from three steps, for a linear one from two, constant from one, and a repeated
    /// load does not make it singular.
    #[test]
    fn predictor_is_exact_for_polynomial_paths() {
        let path = |q: f64| {
            [
                q,
                -1.0 + 0.1 * q - 0.02 * q * q,
                0.5 - 0.3 * q,
                2.0 + q * q,
                -q,
            ]
        };
        let close = |p: [f64; 4], q: f64| {
            p.iter()
                .zip(&path(q)[1..])
                .all(|(a, b)| (a - b).abs() <= 1e-12 * b.abs().max(1.0))
        };
        assert!(predict(&[], 1.0).is_none());
        let three = [path(1.0), path(2.0), path(3.0)];
        assert!(close(predict(&three, 3.5).unwrap(), 3.5));
        let line = |q: f64| [q, 1.0 + q, 2.0 - q, 3.0, 0.5 * q];
        let two = [line(1.0), line(2.0)];
        let p = predict(&two, 4.0).unwrap();
        assert!(
            p.iter()
                .zip(&line(4.0)[1..])
                .all(|(a, b)| (a - b).abs() < 1e-12)
        );
        assert!((predict(&[line(1.0)], 4.0).unwrap()[0] - 2.0).abs() < 1e-15);
        // A repeated load: the duplicate is dropped and the rest is used.
        let repeated = [line(1.0), line(2.0), line(2.0)];
        let p = predict(&repeated, 4.0).unwrap();
        assert!(p.iter().all(|v| v.is_finite()));
        assert!(
            p.iter()
                .zip(&line(4.0)[1..])
                .all(|(a, b)| (a - b).abs() < 1e-12)
        );
    }

    #[test]
    fn transition_table() {
        let tol = 1e-9;
        for (dq, expected) in [
            (1.0, Regime::ForwardSlip),
            (-1.0, Regime::ReverseSlip),
            (0.0, Regime::Stick),
            (1e-12, Regime::Stick),
        ] {
            assert_eq!(next_regime(dq, tol), expected, "dq = {dq}");
        }
        assert_eq!(Regime::ForwardSlip.slip_sign(), Some(1.0));
        assert_eq!(Regime::ReverseSlip.slip_sign(), Some(-1.0));
        assert_eq!(Regime::Stick.slip_sign(), None);
        assert_eq!(Regime::NormalLoading.slip_sign(), None);
    }

    #[test]
    fn history_validation_names_each_point() {
        let h = LoadHistory {
            points: vec![(0.0, 0.0), (1.0, 500.0), (0.5, 700.0)],
            steps_per_segment: 4,
            max_step: 10.0,
        };
        let issues = h.validate("tangential_history", 600.0);
        let paths: Vec<_> = issues.iter().map(|i| i.path.as_str()).collect();
        assert_eq!(
            paths,
            [
                "tangential_history.points[2].q",
                "tangential_history.points[2].t"
            ]
        );
        assert!(issues[0].message.contains("|Q| < ηP"));
        assert!(issues[1].message.contains("must be > previous t = 1 s"));
    }

    #[test]
    fn steps_cover_each_segment_and_holds_take_one_step() {
        let h = LoadHistory {
            points: vec![(0.0, 0.0), (1.0, 10.0), (2.0, 10.0), (3.0, -10.0)],
            steps_per_segment: 2,
            max_step: 4.0,
        };
        let steps = h.steps();
        assert_eq!(steps.len(), 3 + 1 + 5);
        assert!((steps[2].2 - 10.0).abs() < 1e-12 && (steps[3].2 - 10.0).abs() < 1e-12);
        assert!((steps.last().unwrap().2 + 10.0).abs() < 1e-12);
        let cyc =
            LoadHistory::with_cycles(&[(0.0, 0.0), (1.0, 5.0)], &[(1.0, -5.0), (2.0, 5.0)], 2);
        assert_eq!(cyc.len(), 6);
        assert!((cyc[5].0 - 5.0).abs() < 1e-12);
    }
}
