//! One load step: the driver state that outlives a step ([`DriverState`]), and the step itself:
//! tried by [`try_step`] from the committed state and memory ([`solve_slip`] solves and checks
//! it; the driver is left as it was), then committed by [`DriverState::commit`] (phase, memory,
//! anchor, warm start, trace) and finished by [`finish_step`] with its increments and record
//! ([`solve_step`] tries and commits, [`advance`] does all three). A new phase stores the
//! memory of the turning state.

use std::sync::{Arc, OnceLock};

use crate::contact::memory::Memory;
use crate::contact::normal::NormalLoading;
use crate::contact::pressure::Discretisation;
use crate::contact::tangential::{
    PhaseStart, Recalled, SlipOptions, SlipStep, StepAdmissibility, WarmStart, solve_slip,
};
use crate::contact::{ContactModel, ContactState};

use super::general::{SolverKind, ZoneCount};
use super::hints::{
    HISTORY_POINTS, TraceStep, TracedIncrements, Traces, footprint, load_and_geometry,
    phase_start_guess, predict,
};
use super::increments::{IncrementInputs, StepIncrements};
use super::load::LoadPoint;
use super::record::{Observer, StateView, StepFailure, StepRecord};
use super::regime::{PhaseEvent, Regime, next_regime, phase_event};

/// Driver state that outlives a step: plain data, written and read back to the bit
/// ([`crate::history::HistoryState`]).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
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
    #[serde(with = "crate::shared::option")]
    base: Option<Arc<crate::contact::StickZone>>,
    /// Tangential load at the start of the phase (N/m).
    phase_start_load: f64,
    /// Accumulated punch displacement δ (m).
    pub displacement: f64,
    /// The material point at which δ is followed while it sticks (m).
    anchor: f64,
    /// `ux` of the committed state at the anchor, once computed: `(anchor, ux)` (m).
    pub(super) anchor_ux: Option<(f64, f64)>,
    /// Normal approach δn of the current state (m), once computed.
    pub(super) approach: Option<f64>,
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
    /// The phase and the number of take-backs of the general solver's state lost in it (the
    /// spectral solver failed the step right after it took the state back), which postpone
    /// its next try ([`crate::history::GeneralRun::take_back_lost`]).
    #[serde(default)]
    lost_take_backs: (usize, usize),
}

impl DriverState {
    /// A copy to continue the current phase from later ([`super::Turnings`]), without the
    /// recall traces (which only make steps faster, and are the bulk of the state).
    pub(super) fn continuation(&self) -> Self {
        Self {
            state: self.state.clone(),
            memory: self.memory.clone(),
            phase_sign: self.phase_sign,
            phase: self.phase,
            history: self.history.clone(),
            base: self.base.clone(),
            phase_start_load: self.phase_start_load,
            displacement: self.displacement,
            anchor: self.anchor,
            anchor_ux: self.anchor_ux,
            approach: self.approach,
            warm: self.warm,
            first_centre_slope: self.first_centre_slope,
            traces: super::hints::Traces::default(),
            last_start: self.last_start,
            lost_take_backs: self.lost_take_backs,
        }
    }

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
            lost_take_backs: (0, 0),
        }
    }

    /// A take-back of the general solver's state in the current phase was lost: the number
    /// lost before it in the phase (0 for the first).
    pub fn take_back_lost(&mut self) -> usize {
        let (phase, count) = self.lost_take_backs;
        let before = if phase == self.phase { count } else { 0 };
        self.lost_take_backs = (self.phase, before + 1);
        before
    }
}

/// Advance the driver by one load step: solve it ([`solve_step`]), compute its increments
/// ([`StepIncrements::compute`]) and commit them ([`finish_step`]).
#[cfg(any(test, feature = "internals"))]
pub fn advance(
    model: &ContactModel,
    disc: &Discretisation,
    driver: &mut DriverState,
    point: LoadPoint,
    options: SlipOptions,
    observer: &mut dyn Observer,
) -> Result<StepRecord, StepFailure> {
    Ok(match solve_step(model, disc, driver, point, options)? {
        Solved::Hold(regime) => {
            let rec = hold_record(driver, point, regime);
            observer.on_step(&rec, StateView::Spectral(&driver.state));
            rec
        }
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
#[cfg(any(test, feature = "internals"))]
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
    pub(super) inputs: IncrementInputs,
    /// The phase this step begins, with its memory (for the observer).
    new_phase: Option<(usize, Memory)>,
    /// The increments, when the step reproduced a recalled step whose increments are known.
    pub(super) known: Option<StepIncrements>,
    /// Where the step's increments are kept for a later phase that recalls it.
    trace: Option<Arc<OnceLock<(f64, StepIncrements)>>>,
}

impl SolvedStep {
    /// The step's record without the increments.
    pub fn record(&self) -> &StepRecord {
        &self.record
    }
}

/// The record of a hold step (nothing changes; the observer's view of it is the driver's
/// state).
pub(super) fn hold_record(driver: &DriverState, point: LoadPoint, regime: Regime) -> StepRecord {
    let mut rec = record(point.step, point.t, driver, regime, None);
    rec.q = point.q;
    rec
}

/// Commit a solved step's increments to the driver (δ, the anchor's ux, δn) and pass its
/// record to the observer (after the phase it begins, if any): [`settle_step`], then
/// [`observe_step`]. Steps must be finished in order.
pub fn finish_step(
    driver: &mut DriverState,
    solved: SolvedStep,
    increments: StepIncrements,
    observer: &mut dyn Observer,
) -> StepRecord {
    let rec = settle_step(driver, &solved, increments);
    observe_step(observer, &rec, &solved);
    rec
}

/// Commit a solved step's increments to the driver (δ, the anchor's ux, δn) and return its
/// full record, which no observer has seen yet ([`observe_step`]). Steps must be settled in
/// order.
pub(super) fn settle_step(
    driver: &mut DriverState,
    solved: &SolvedStep,
    increments: StepIncrements,
) -> StepRecord {
    if let Some(cell) = &solved.trace {
        // Set once: a step is finished once.
        let _ = cell.set((solved.inputs.anchor, increments));
    }
    driver.anchor_ux = Some((solved.inputs.anchor, increments.new_ux));
    driver.approach = Some(increments.new_approach);
    driver.displacement += increments.displacement;
    let mut rec = solved.record.clone();
    rec.displacement = driver.displacement;
    rec.dissipation = increments.dissipation;
    rec.normal_work = increments.normal_work;
    rec.electric_work = increments.electric_work;
    rec
}

/// Pass a settled step's record `rec` to the observer, after the phase it begins, if any.
pub(super) fn observe_step(observer: &mut dyn Observer, rec: &StepRecord, solved: &SolvedStep) {
    if let Some((phase, memory)) = &solved.new_phase {
        observer.on_phase(*phase, memory);
    }
    observer.on_step(rec, StateView::Spectral(&solved.inputs.new));
}

/// Solve one load step and commit its state to the driver (phase, memory, anchor, warm
/// start): [`try_step`], then [`DriverState::commit`]; its increments are left to
/// [`finish_step`].
#[cfg(any(test, feature = "internals"))]
pub fn solve_step(
    model: &ContactModel,
    disc: &Discretisation,
    driver: &mut DriverState,
    point: LoadPoint,
    options: SlipOptions,
) -> Result<Solved, StepFailure> {
    Ok(match try_step(model, disc, driver, point, options)? {
        Tried::Hold(regime) => Solved::Hold(regime),
        Tried::Slip(trial) => Solved::Slip(Box::new(driver.commit(*trial))),
    })
}

/// A step tried from the committed state: a hold, or a slip step to commit
/// ([`DriverState::commit`]) or drop.
pub enum Tried {
    /// ΔQ = 0 (the regime is [`Regime::Stick`]): nothing changes.
    Hold(Regime),
    /// A solved slip step.
    Slip(Box<Trial>),
}

/// A slip step solved from the committed state, not yet committed: its state, and what the
/// commit stores with it.
pub struct Trial {
    point: LoadPoint,
    regime: Regime,
    sign: f64,
    /// The solver's step.
    pub solved: SlipStep,
    /// The phase the step begins, if it begins one: the memory it keeps, its base zone and the
    /// load it begins at.
    begins: Option<PhaseBegin>,
    /// `[Q, lo, hi, a, c]` of the state the step's phase began from.
    phase_start: Option<[f64; 5]>,
    /// The same step of the last phase in this direction from the same turning state.
    traced: Option<TraceStep>,
    /// The footprint of the state the step began from.
    from: super::hints::Footprint,
    /// Whether the step converged to the tolerance (only such steps are traced).
    converged: bool,
}

/// What a step that begins a phase stores.
struct PhaseBegin {
    memory: Memory,
    base: Option<Arc<crate::contact::StickZone>>,
    start_load: f64,
}

impl Trial {
    /// The record the step will have once committed to `driver` (the driver it was tried
    /// from), without its increments.
    pub fn record(&self, driver: &DriverState) -> StepRecord {
        let phase = driver.phase + usize::from(self.begins.is_some());
        record_of(
            (self.point.step, self.point.t),
            &self.solved.state,
            (phase, driver.displacement),
            self.regime,
            Some(&self.solved),
        )
    }
}

/// Solve one load step from the driver's committed state, which it leaves as it is (but for
/// the tables of the turning state, built once a phase begins from it).
///
/// The step's regime follows from ΔQ ([`next_regime`]) and whether it begins a phase from
/// the phase rule ([`phase_event`]). A phase stores the memory of the turning state
/// ([`Memory::committed`]); its first step starts from the Mindlin–Deresiewicz guess
/// (`phase_start_guess`), the others from the geometry extrapolated in Q (`predict`), the
/// previous Jacobian and the recalled step of a repeated phase (module docs).
pub fn try_step(
    model: &ContactModel,
    disc: &Discretisation,
    driver: &DriverState,
    point: LoadPoint,
    options: SlipOptions,
) -> Result<Tried, StepFailure> {
    let LoadPoint { step, t, q, .. } = point;
    let dq = q - driver.state.tangential_load;
    let limit = model.friction * driver.state.normal_load;
    let regime = next_regime(dq, 1e-12 * limit);
    let Some(sign) = regime.slip_sign() else {
        return Ok(Tried::Hold(regime));
    };
    let new_phase = matches!(phase_event(driver.phase_sign, regime), PhaseEvent::Begin(_));
    let begins = new_phase.then(|| begin_phase(disc, driver));
    let (memory, base, start_load) = match &begins {
        Some(b) => (&b.memory, b.base.as_ref(), b.start_load),
        None => (
            &driver.memory,
            driver.base.as_ref(),
            driver.phase_start_load,
        ),
    };
    let continuation = options.accelerations.continuation;
    let (guesses, contact) = starting_geometry(
        model,
        driver,
        (q, sign, dq),
        (new_phase, continuation),
        start_load,
    );
    // The same step of the last phase in this direction that began from the same turning
    // state: in a steady cycle it solves this step again.
    let phase_start = if new_phase {
        Some(load_and_geometry(&driver.state))
    } else {
        driver.traces.current.as_ref().map(|t| t.start)
    };
    let traced = phase_start
        .filter(|_| options.accelerations.recall)
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
        memory,
        base,
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
    // A step accepted at a stalled residual is not recalled: the next cycle's step tries to
    // converge (default history at M = 64 with 20 steps per segment: the step at −0.075 ηP
    // stalled at 1.4e−6 in the second cycle and converged from its own path in the third).
    let converged = solved.residual < options.tolerance;
    Ok(Tried::Slip(Box::new(Trial {
        point,
        regime,
        sign,
        solved,
        begins,
        phase_start,
        traced,
        from,
        converged,
    })))
}

/// The memory, base and starting load of a phase that begins from the driver's state.
fn begin_phase(disc: &Discretisation, driver: &DriverState) -> PhaseBegin {
    if let Some(zone) = driver.state.traction.stick.as_ref() {
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
    let memory = match (&driver.phase_sign, driver.state.traction.stick.as_ref()) {
        (Some(_), Some(s)) => driver
            .memory
            .committed(Arc::new(driver.state.clone()), s.lo, s.hi),
        _ => driver.memory.clone(),
    };
    PhaseBegin {
        memory,
        base: driver.state.traction.stick.clone().map(Arc::new),
        start_load: driver.state.tangential_load,
    }
}

/// Two guesses of the stick ends `(lo, hi)`, in the order they are tried, and the contact's
/// half-width and centre `(a, c)` to start from, when known.
type StartingGeometry = ([(f64, f64); 2], Option<(f64, f64)>);

/// The stick-end guesses of a step to load `q` (slip sign `sign`, load change `dq`) and the
/// contact's half-width and centre to start from (module docs, "Warm start").
fn starting_geometry(
    model: &ContactModel,
    driver: &DriverState,
    (q, sign, dq): (f64, f64, f64),
    (new_phase, continuation): (bool, bool),
    start_load: f64,
) -> StartingGeometry {
    let limit = model.friction * driver.state.normal_load;
    let predicted = (!new_phase && continuation)
        .then(|| predict(&driver.history, q))
        .flatten();
    let guess = match predicted {
        Some([lo, hi, ..]) => (lo, hi),
        None => phase_start_guess(model, &driver.state, sign, dq),
    };
    // Second guess: the Mindlin–Deresiewicz size for the load change since the phase began,
    // centred on the contact.
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
    let contact = if !continuation {
        None
    } else if new_phase {
        driver.first_centre_slope.map(|slope| (a, c + slope * dq))
    } else {
        predicted.map(|[.., a, c]| (a, c))
    };
    (guesses, contact)
}

impl DriverState {
    /// Commit a step tried from this state ([`try_step`]): the phase it begins (memory, base,
    /// phase number), the anchor of δ, the warm start and predictor of the next step, and the
    /// trace of the phase. Its increments are left to [`finish_step`].
    pub fn commit(&mut self, trial: Trial) -> SolvedStep {
        let Trial {
            point,
            regime,
            sign,
            solved,
            begins,
            phase_start,
            traced,
            from,
            converged,
        } = trial;
        let new_phase = begins.is_some();
        if let Some(PhaseBegin {
            memory,
            base,
            start_load,
        }) = begins
        {
            if let Some(start) = PhaseStart::of(&solved.state, sign) {
                self.last_start = Some(start);
            }
            let dq = point.q - self.state.tangential_load;
            self.first_centre_slope = Some((solved.state.centre - self.state.centre) / dq);
            self.phase += 1;
            self.phase_start_load = start_load;
            self.phase_sign = Some(sign);
            self.memory = memory;
            self.base = base;
            self.history.clear();
        }
        self.move_anchor(&solved.state);
        self.warm = Some(WarmStart {
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
            .and_then(|t| t.increments.for_repeat(self.anchor));
        let old = std::mem::replace(&mut self.state, solved.state.clone());
        self.history.push(load_and_geometry(&self.state));
        if self.history.len() > HISTORY_POINTS {
            self.history.remove(0);
        }
        let record = record(point.step, point.t, self, regime, Some(&solved));
        let new = Arc::new(solved.state);
        let increments = Arc::new(OnceLock::new());
        let trace = converged.then(|| TraceStep {
            q: point.q,
            recalled: Recalled {
                state: Arc::clone(&new),
                warm: self.warm.expect("set above"),
                admissibility: Some(solved.admissibility),
            },
            increments: TracedIncrements {
                from,
                value: Arc::clone(&increments),
            },
        });
        self.traces
            .push(phase_start.filter(|_| new_phase), sign, trace);
        SolvedStep {
            record,
            inputs: IncrementInputs {
                old: Arc::new(old),
                new,
                anchor: self.anchor,
                old_ux: None,
                old_approach: None,
            },
            new_phase: new_phase.then(|| (self.phase, self.memory.clone())),
            known,
            trace: converged.then_some(increments),
        }
    }

    /// Keep the anchor of δ while it sticks in the new state; otherwise take the middle of the
    /// part of the old stick zone that still sticks.
    fn move_anchor(&mut self, new: &ContactState) {
        let new_zone = new.traction.stick.as_ref().expect("slip state");
        let margin = 1e-3 * (new_zone.hi - new_zone.lo);
        if self.anchor > new_zone.lo + margin && self.anchor < new_zone.hi - margin {
            return;
        }
        let (lo, hi) = self
            .state
            .traction
            .stick
            .as_ref()
            .map_or((new_zone.lo, new_zone.hi), |z| {
                (z.lo.max(new_zone.lo), z.hi.min(new_zone.hi))
            });
        self.anchor = if hi > lo {
            0.5 * (lo + hi)
        } else {
            new_zone.mid()
        };
    }
}

/// The record of the driver's committed state, with zero increments (a hold's; a slip step's
/// are filled in by [`finish_step`]).
pub(super) fn record(
    step: usize,
    t: f64,
    driver: &DriverState,
    regime: Regime,
    solved: Option<&SlipStep>,
) -> StepRecord {
    record_of(
        (step, t),
        &driver.state,
        (driver.phase, driver.displacement),
        regime,
        solved,
    )
}

/// The record of state `s` at step `step` and time `t`, in phase `phase` with δ `displacement`,
/// with zero increments.
fn record_of(
    (step, t): (usize, f64),
    s: &ContactState,
    (phase, displacement): (usize, f64),
    regime: Regime,
    solved: Option<&SlipStep>,
) -> StepRecord {
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
        normal_load: s.normal_load,
        bulk_stress: 0.0,
        charge: s.charge,
        potential: s.potential.unwrap_or(0.0),
        regime,
        phase,
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
        displacement,
        dissipation: 0.0,
        normal_work: 0.0,
        electric_work: 0.0,
        solver: SolverKind::Spectral,
        zones: ZoneCount::of_spectral(s),
    }
}
