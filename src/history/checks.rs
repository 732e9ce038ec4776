//! The general solver's checks of the spectral solver's steps under `numerics.solver = auto`:
//! the first step of every phase ([`contradicted`]: the zone structure and the ends, where
//! thin end layers that slip the old way form in a coupled contact) and every turning point
//! ([`turning_checked`]: the shear tractions), and how a spectral stretch runs them beside
//! the steps that follow them ([`Checks`], [`Held`]).
//!
//! # Beside the steps
//! A check needs the state before its step, the step's load and what the spectral solver made
//! of the step; the steps after it need nothing from the check unless it contradicts. With
//! [`Accelerations::concurrent_checks`] the checks run on a thread of their own (one for a
//! stretch of spectral steps, which holds the general solver's recall), one after another in
//! the order of their steps, while the spectral solver takes the next steps on the run's
//! thread. What the
//! observer sees of a step, the turning points' checkpoints and the run's records wait
//! ([`Held`]) until every check up to that step has agreed (each check sends its verdict as
//! it ends); beyond `OPEN_CHECKS` open checks (`history::run`) the spectral solver waits for
//! the oldest. A check that contradicts takes
//! the driver back to the state before its step (a copy kept when the step was committed)
//! and the steps after it are dropped, as if they had never been tried: the records, the
//! turning states and every call of the observer are those of the checks run in turn (test
//! `checks_beside_the_steps_give_the_run_of_checks_in_turn`). Off, each check is taken when
//! its step has been tried, before the step is committed.
//!
//! [`Accelerations::concurrent_checks`]: crate::contact::tangential::Accelerations::concurrent_checks

use std::collections::VecDeque;
use std::sync::mpsc::{Receiver, Sender};
use std::thread::{Scope, ScopedJoinHandle};

use crate::contact::general::{Loads, Recall};
use crate::contact::{ContactModel, ContactState};
use crate::error::SolveFailure;

use super::driver::{DriverState, SolvedStep, observe_step};
use super::general::{GeneralRun, RunOptions, ZoneCount};
use super::load::LoadPoint;
use super::record::{Observer, StateView, StepFailure, StepRecord};
use super::regime::Regime;
use super::state::HistoryStateView;
use super::turnings::Turnings;

/// A check's contradiction: why the step is handed over, and the general solver's run and
/// record of it.
pub(super) type Handover = (StepFailure, (GeneralRun, StepRecord));

/// What the spectral solver made of a checked step.
pub(super) enum Claim {
    /// The record of a phase's first step ([`contradicted`]).
    PhaseStart(StepRecord),
    /// The state at a turning point ([`turning_checked`]).
    Turning(ContactState),
}

/// One check: the step's index in the stretch, the driver's state before it (without the
/// recall traces), its load and the spectral solver's claim.
struct Job {
    at: usize,
    before: DriverState,
    point: LoadPoint,
    claim: Claim,
}

impl Job {
    fn run(
        &self,
        model: &ContactModel,
        options: RunOptions,
        recall: &mut Recall,
    ) -> Option<Handover> {
        let (before, point) = (&self.before, (self.point, options));
        match &self.claim {
            Claim::PhaseStart(record) => contradicted(model, before, point, record, recall),
            Claim::Turning(state) => turning_checked(model, before, point, state, recall),
        }
    }
}

/// A check's verdict, as each check sends it when it is done: its step's index, and the
/// handover if it contradicts.
type Verdict = (usize, Option<Box<Handover>>);

/// The thread that runs a stretch's checks in turn, with the run's recall: where the checks
/// go, and the thread, which gives the recall back when the checks end.
struct Worker<'scope, 'r> {
    jobs: Sender<Job>,
    thread: ScopedJoinHandle<'scope, &'r mut Recall>,
}

/// A check that contradicted its step at index `at` (the first in step order that did): the
/// handover, and the driver before that step when the step was committed since (else the
/// driver is still there).
pub(super) struct Contradiction {
    pub(super) at: usize,
    pub(super) handover: Box<Handover>,
    pub(super) before: Option<Box<DriverState>>,
}

/// The general solver's checks of a spectral stretch, in the order of their steps, on a
/// thread of their own (one for the stretch) or in turn ([`Accelerations::concurrent_checks`]).
/// Each sends its verdict when it is done, so that the steps before the next open check are
/// verified as soon as the checks before them agree; after a contradiction the later checks
/// are not run.
///
/// [`Accelerations::concurrent_checks`]: crate::contact::tangential::Accelerations::concurrent_checks
pub(super) struct Checks<'scope, 'env, 'r> {
    scope: &'scope Scope<'scope, 'env>,
    model: &'env ContactModel,
    options: RunOptions,
    /// The checks' thread, once a check has started (concurrent checks).
    worker: Option<Worker<'scope, 'r>>,
    /// The run's recall, unless the checks' thread holds it.
    recall: Option<&'r mut Recall>,
    verdicts: (Sender<Verdict>, Receiver<Verdict>),
    /// Whether a check taken in turn contradicted its step (the later ones are then not run).
    contradicted: bool,
    /// The steps whose checks are not resolved, in order, each with the driver before it
    /// once the step is committed.
    open: VecDeque<(usize, Option<Box<DriverState>>)>,
}

impl<'scope, 'env: 'scope, 'r: 'scope> Checks<'scope, 'env, 'r> {
    pub(super) fn new(
        scope: &'scope Scope<'scope, 'env>,
        model: &'env ContactModel,
        options: RunOptions,
        recall: &'r mut Recall,
    ) -> Self {
        Self {
            scope,
            model,
            options,
            worker: None,
            recall: Some(recall),
            verdicts: std::sync::mpsc::channel(),
            contradicted: false,
            open: VecDeque::new(),
        }
    }

    /// Start the check of the step at index `at` (load `point`) from `before`, of the
    /// spectral solver's `claim`: after the checks started before it, and only if they agree.
    pub(super) fn start(
        &mut self,
        at: usize,
        before: &DriverState,
        point: LoadPoint,
        claim: Claim,
    ) {
        let job = Job {
            at,
            before: before.continuation(),
            point,
            claim,
        };
        let (model, options) = (self.model, self.options);
        self.open.push_back((at, None));
        if !options.slip.accelerations.concurrent_checks {
            // As on the checks' thread: none after a contradiction.
            if !self.contradicted {
                let recall = (self.recall.as_deref_mut()).expect("checks in turn keep the recall");
                let handover = job.run(model, options, recall).map(Box::new);
                self.contradicted = handover.is_some();
                let _ = self.verdicts.0.send((at, handover));
            }
            return;
        }
        if self.worker.is_none() {
            let (jobs, inbox) = std::sync::mpsc::channel::<Job>();
            let verdicts = self.verdicts.0.clone();
            let recall = self.recall.take().expect("the recall is back");
            let thread = self.scope.spawn(move || {
                let mut contradicted = false;
                for job in inbox {
                    if contradicted {
                        continue;
                    }
                    let handover = job.run(model, options, recall).map(Box::new);
                    contradicted = handover.is_some();
                    // The receiver lives as long as the stretch, which joins this thread.
                    let _ = verdicts.send((job.at, handover));
                }
                // A thread per stretch: what its allocator kept would stay resident after it
                // (a steady history begins a stretch at every take-back).
                crate::shared::release_thread_memory();
                recall
            });
            self.worker = Some(Worker { jobs, thread });
        }
        let worker = self.worker.as_ref().expect("started above");
        worker
            .jobs
            .send(job)
            .expect("the checks' thread runs until the stretch ends");
    }

    /// Before the step at index `at` is committed to `driver`: keep the driver's state for
    /// the step's check, if it is open, to take the run back to.
    pub(super) fn committing(&mut self, at: usize, driver: &DriverState) {
        if let Some((_, kept @ None)) = self.open.iter_mut().find(|(k, _)| *k == at) {
            *kept = Some(Box::new(driver.clone()));
        }
    }

    /// The index of the first step whose check is open: every step before it is verified.
    pub(super) fn verified_below(&self) -> usize {
        self.open.front().map_or(usize::MAX, |&(k, _)| k)
    }

    /// The verdicts of the checks done so far, in order, waiting for them while more than
    /// `open` checks are open: the checks that agreed are resolved, and the first
    /// contradiction is returned (the checks after it are dropped).
    pub(super) fn resolve(&mut self, open: usize) -> Option<Contradiction> {
        while !self.open.is_empty() {
            let verdict = if self.open.len() > open {
                self.verdicts.1.recv().ok()
            } else {
                self.verdicts.1.try_recv().ok()
            };
            let Some((at, handover)) = verdict else {
                break;
            };
            let (step, before) = self.open.pop_front().expect("an open check");
            debug_assert_eq!(step, at, "verdicts come in the order of their steps");
            if let Some(handover) = handover {
                self.open.clear();
                return Some(Contradiction {
                    at,
                    handover,
                    before,
                });
            }
        }
        None
    }

    /// The general solver's recall, once every check has ended (the checks' thread is ended
    /// and gives it back).
    pub(super) fn recall(&mut self) -> &mut Recall {
        if let Some(Worker { jobs, thread }) = self.worker.take() {
            drop(jobs);
            self.recall = Some(thread.join().expect("a check does not panic"));
        }
        self.recall.as_deref_mut().expect("the recall is back")
    }
}

/// What the observer and the run's records are still to see of the steps a spectral stretch
/// took, in order, until the checks before them have agreed ([`Checks::verified_below`]).
#[derive(Default)]
pub(super) struct Held(VecDeque<Seen>);

/// A step, or a turning point's checkpoint, as the observer is to see it.
enum Seen {
    /// The step at index `at` from the load `from` to `to`, its record and state.
    Step {
        at: usize,
        from: f64,
        to: f64,
        record: Box<StepRecord>,
        state: StepState,
    },
    /// The end of the phase at the turning point at index `at`, load `q`: the driver there.
    Turning {
        at: usize,
        q: f64,
        driver: Box<DriverState>,
    },
}

/// The state the observer sees of a step.
pub(super) enum StepState {
    /// A slip step, settled ([`super::driver::settle_step`]).
    Slip(Box<SolvedStep>),
    /// A hold: the driver's state.
    Hold(Box<ContactState>),
}

/// Where the records and the turning states go as steps are seen.
pub(super) struct Sink<'a> {
    pub(super) observer: &'a mut dyn Observer,
    pub(super) turnings: &'a mut Turnings,
    pub(super) records: &'a mut Vec<StepRecord>,
    pub(super) keep_records: bool,
}

impl Sink<'_> {
    fn see_step(&mut self, (from, to): (f64, f64), record: StepRecord, state: &StepState) {
        match state {
            StepState::Slip(solved) => observe_step(self.observer, &record, solved),
            StepState::Hold(state) => self.observer.on_step(&record, StateView::Spectral(state)),
        }
        self.turnings.step(from, to);
        super::run::keep(self.records, record, self.keep_records);
    }

    /// The phase's end at the turning point `q` with the driver there, and its checkpoint;
    /// whether the observer asks the run to end.
    fn see_turning(&mut self, q: f64, driver: &DriverState) -> bool {
        self.turnings.end_phase(q, Some(driver));
        let view = HistoryStateView {
            driver: Some(driver),
            general: None,
            turnings: self.turnings,
        };
        self.observer
            .on_checkpoint(self.records.last().expect("a step was seen"), view);
        self.observer.stop()
    }
}

/// Where showing the held steps ended.
pub(super) enum Shown {
    /// Every verified step was shown.
    Done,
    /// The observer asked the run to end at a turning point; the driver is set back there.
    Stop,
}

impl Held {
    /// Add the step at index `at` from the load `from` to `to`.
    pub(super) fn step(
        &mut self,
        (at, from, to): (usize, f64, f64),
        record: StepRecord,
        state: StepState,
    ) {
        self.0.push_back(Seen::Step {
            at,
            from,
            to,
            record: Box::new(record),
            state,
        });
    }

    /// Show the held steps below index `below` to `sink`, then the turning point at index
    /// `at` (load `q`, the driver there) if it is below too, else hold it (with a copy of the
    /// driver).
    pub(super) fn turning(
        &mut self,
        (at, q, below): (usize, f64, usize),
        driver: &mut DriverState,
        sink: &mut Sink,
    ) -> Shown {
        if let Shown::Stop = self.show(below, driver, sink) {
            return Shown::Stop;
        }
        if at < below && self.0.is_empty() {
            return if sink.see_turning(q, driver) {
                Shown::Stop
            } else {
                Shown::Done
            };
        }
        self.0.push_back(Seen::Turning {
            at,
            q,
            driver: Box::new(driver.clone()),
        });
        Shown::Done
    }

    /// Show the held steps below index `below` to `sink`, in order; at a turning point where
    /// the observer asks the run to end, set the driver back there and drop the rest.
    pub(super) fn show(
        &mut self,
        below: usize,
        driver: &mut DriverState,
        sink: &mut Sink,
    ) -> Shown {
        while let Some(seen) = self.0.front() {
            let at = match seen {
                Seen::Step { at, .. } | Seen::Turning { at, .. } => *at,
            };
            if at >= below {
                break;
            }
            match self.0.pop_front().expect("a front") {
                Seen::Step {
                    from,
                    to,
                    record,
                    state,
                    ..
                } => sink.see_step((from, to), *record, &state),
                Seen::Turning {
                    q, driver: there, ..
                } => {
                    if sink.see_turning(q, &there) {
                        *driver = *there;
                        self.0.clear();
                        return Shown::Stop;
                    }
                }
            }
        }
        Shown::Done
    }

    /// Drop the held steps at index `from` and after (a check contradicted that step).
    pub(super) fn drop_from(&mut self, from: usize) {
        self.0.retain(|seen| match seen {
            Seen::Step { at, .. } | Seen::Turning { at, .. } => *at < from,
        });
    }
}

/// Where the general solver's record of a step and the spectral solver's describe different
/// states, if they do: another phase, another zone structure at the element resolution (a
/// zone of one element is not a contradiction: [`ZoneCount::resolved`]), or a contact or
/// stick end more than two elements of the general solver's mesh there from the other's.
pub(super) fn disagreement(
    run: &GeneralRun,
    general: &StepRecord,
    spectral: &StepRecord,
) -> Option<String> {
    if spectral.phase != general.phase {
        return Some(format!(
            "the general solver's step is in phase {} where the spectral solver's is in phase {}",
            general.phase, spectral.phase
        ));
    }
    let resolved = ZoneCount::resolved(&run.state);
    if spectral.zones != resolved {
        return Some(format!(
            "the general solver finds {} stick and {} slip zones ({} slip sign changes) where \
             the spectral solver's state has {} and {} ({} slip sign changes)",
            resolved.stick,
            resolved.slip,
            resolved.sign_changes,
            spectral.zones.stick,
            spectral.zones.slip,
            spectral.zones.sign_changes
        ));
    }
    let ends = |r: &StepRecord| {
        let c = -r.eccentricity;
        [c - r.half_width, c + r.half_width, r.stick_lo, r.stick_hi]
    };
    let names = [
        "left contact end",
        "right contact end",
        "left stick end",
        "right stick end",
    ];
    ends(general)
        .into_iter()
        .zip(ends(spectral))
        .zip(names)
        .map(|((g, s), name)| (name, g, s, (g - s).abs() / run.state.mesh.width_at(g)))
        .filter(|&(.., elements)| elements > 2.0)
        .max_by(|x, y| x.3.total_cmp(&y.3))
        .map(|(name, g, s, elements)| {
            format!(
                "the general solver's {name} is at {g:.6e} m, the spectral solver's at \
                 {s:.6e} m ({elements:.1} elements apart; the same zones)"
            )
        })
}

/// The general solver's check of the first step of a phase, which the spectral solver took
/// from `before` with the record `spectral`: when the general solver finds another state (end
/// layers the spectral form cannot hold), the reason to hand the step over and the general
/// solver's run and record of it; `None` when it agrees or cannot take the step itself.
pub(super) fn contradicted(
    model: &ContactModel,
    before: &DriverState,
    (point, options): (LoadPoint, RunOptions),
    spectral: &StepRecord,
    recall: &mut Recall,
) -> Option<Handover> {
    let mut run = GeneralRun::handover(model, before, options.general_element_size, recall);
    let general = run.step(model, point, recall).ok()?;
    let reason = disagreement(&run, &general, spectral)?;
    Some((
        handover_reason(point, spectral.regime, reason),
        (run, general),
    ))
}

/// Why a check hands the spectral solver's step at `point` over to the general solver.
fn handover_reason(point: LoadPoint, regime: Regime, reason: String) -> StepFailure {
    StepFailure {
        step: point.step,
        t: point.t,
        q: point.q,
        regime,
        failure: SolveFailure::NoAdmissibleState { reason },
    }
}

/// The general solver's check of a turning point, which the spectral solver took from
/// `before` to the state `spectral`: the general solver takes the same step, handed over from
/// `before` onto the mesh made for `spectral` (which the check of the next phase's first step
/// then finds in `recall`), and the two states' shear tractions must be within
/// [`TURNING_SHEAR`] ([`Solver::traction_distance`]). When they are not, the reason to hand
/// the step over and the general solver's run and record of it; `None` when they are or the
/// general solver cannot take the step. The tractions, not the zone ends: a band at the
/// friction limit holds `|q| = ηp` whether a solver counts it stuck or slipping
/// (docs/validation.md), and the two solvers' stick ends there can be far apart with the same
/// tractions.
///
/// [`Solver::traction_distance`]: crate::contact::general::Solver::traction_distance
pub(super) fn turning_checked(
    model: &ContactModel,
    before: &DriverState,
    (point, options): (LoadPoint, RunOptions),
    spectral: &ContactState,
    recall: &mut Recall,
) -> Option<Handover> {
    let size = options.general_element_size;
    let mut run = GeneralRun::handover_onto(model, before, spectral, size, recall);
    // The check to a tolerance its bound allows; a step it contradicts, to the solver's own.
    let loads = Loads {
        tangential: point.q,
        ..run.state.loads
    };
    let (checked, _) = recall
        .step_to_tolerance(run.solver(), &run.state, loads, CHECK_TOLERANCE)
        .ok()?;
    if run.solver().traction_distance(spectral, &checked)[1] <= TURNING_SHEAR {
        return None;
    }
    let record = run.step(model, point, recall).ok()?;
    let [_, shear] = run.solver().traction_distance(spectral, &run.state);
    if shear <= TURNING_SHEAR {
        return None;
    }
    let reason = format!(
        "at the turning point the general solver's shear tractions are {shear:.3e} of ηP from \
         the spectral solver's (L1 norm of the element means; at most {TURNING_SHEAR:e})"
    );
    Some((handover_reason(point, record.regime, reason), (run, record)))
}

/// The largest distance of the shear tractions at which the general solver's check of a
/// turning point agrees with the spectral solver's state ([`turning_checked`]). Measured on
/// turning states the spectral solver got right: the default history's seven at 7.9e−5 to
/// 1.2e−4; the default contact's first 400 random reversals (`random.seed(7)`), 216 at
/// 8.3e−5 to 8.0e−3, the largest where the stick zone remembers several earlier ones. A state
/// with another memory at the same load: 0.195 (the test of [`turning_checked`]); the replays
/// refused by [`TAKE_BACK_SHEAR`], 0.034 to 0.11.
///
/// [`TAKE_BACK_SHEAR`]: super::run::TAKE_BACK_SHEAR
const TURNING_SHEAR: f64 = 1e-2;

/// The outer tolerance of the general solver's step in the check of a turning point
/// ([`turning_checked`]): the step's tractions are then within about 2e−5 of ηp of the
/// converged ones, far inside [`TURNING_SHEAR`].
const CHECK_TOLERANCE: f64 = 1e-4;
