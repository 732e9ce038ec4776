//! The loop over a load history: [`run_history`] from the normal loading and [`continue_run`]
//! from any driver state, each solving a step while the previous step's increments are
//! computed on a second thread; the run's result ([`HistoryRun`]) and failure
//! ([`HistoryFailure`]).

use crate::contact::ContactModel;
use crate::contact::general::Recall;
use crate::contact::pressure::Discretisation;
use crate::contact::tangential::SlipOptions;
use crate::error::SolveFailure;

use super::checks::{Checks, Claim, Contradiction, Held, Shown, Sink, StepState, disagreement};
use super::driver::{
    DriverState, SolvedStep, Trial, Tried, finish_step, hold_record, settle_step, try_step,
};
use super::general::{GeneralRun, RunOptions, SolverChoice, SolverKind};
use super::increments::{IncrementInputs, StepIncrements};
use super::load::{Control, LoadHistory, LoadPoint, PunchLoads};
use super::normal::NormalEnd;
use super::record::{NoObserver, Observer, StateView, StepFailure, StepRecord};
use super::regime::{PhaseEvent, Regime, next_regime, phase_event};
use super::state::HistoryState;
use super::turnings::Turnings;

/// A finished run: the records and the final state.
#[derive(Debug, Clone)]
pub struct HistoryRun {
    /// One record per accepted step (step 0 = end of normal loading); the last one only
    /// without [`RunOptions::keep_records`].
    pub records: Vec<StepRecord>,
    /// The state after the last step.
    pub state: HistoryState,
}

/// A failed run: what was accepted before the failure, and the failure.
#[derive(Debug, Clone)]
pub struct HistoryFailure {
    /// The steps accepted before the failure (the last one only without
    /// [`RunOptions::keep_records`]).
    pub records: Vec<StepRecord>,
    /// The state at the last accepted step.
    pub state: HistoryState,
    /// The failed step.
    pub failure: StepFailure,
}

/// Walk a whole history from the end of normal loading.
pub fn run_history(
    model: &ContactModel,
    disc: &Discretisation,
    normal: &NormalEnd,
    history: &LoadHistory,
    options: RunOptions,
    observer: &mut dyn Observer,
) -> Result<HistoryRun, Box<HistoryFailure>> {
    let t0 = history.points.first().map_or(0.0, |p| p.0);
    let records = vec![normal.record(t0)];
    observer.on_step(&records[0], normal.view());
    let mut state = normal.history_state();
    if history.control == Control::Displacement {
        // The spectral solver prescribes Q: the general solver holds every step.
        let mut recall = Recall::new(options.slip.accelerations.general_recall);
        general_from_here(model, &mut state, options.general_element_size, &mut recall);
        if let Some(run) = state.general.as_mut() {
            run.control = Control::Displacement;
        }
    }
    let points = history.load_points();
    run_from(model, disc, (state, records), &points, options, observer)
}

/// Walk `points` from `state`, after the steps `records` taken to reach it, as
/// [`continue_run`] does: the finished run, or what was accepted before a failure.
pub fn run_from(
    model: &ContactModel,
    disc: &Discretisation,
    (mut state, mut records): (HistoryState, Vec<StepRecord>),
    points: &[LoadPoint],
    options: RunOptions,
    observer: &mut dyn Observer,
) -> Result<HistoryRun, Box<HistoryFailure>> {
    let failure = continue_run(
        model,
        disc,
        &mut state,
        points,
        options,
        observer,
        &mut records,
    );
    match failure {
        None => Ok(HistoryRun { records, state }),
        Some(failure) => Err(Box::new(HistoryFailure {
            records,
            state,
            failure,
        })),
    }
}

/// Which of `points` are turning points of the load, taken from the load `q` (a point
/// followed by a step the other way, after any holds), and the last point: where a run
/// passes its state to [`Observer::on_checkpoint`].
pub fn turning_points(q: f64, points: &[LoadPoint]) -> Vec<bool> {
    let mut turning = vec![false; points.len()];
    let mut last_move: Option<(usize, f64)> = None;
    let mut before = q;
    for (k, p) in points.iter().enumerate() {
        let dq = p.q - before;
        before = p.q;
        if dq.abs() > 0.0 {
            if let Some((at, sign)) = last_move
                && sign * dq < 0.0
            {
                turning[at] = true;
            }
            last_move = Some((k, dq.signum()));
        }
    }
    if let Some(last) = turning.last_mut() {
        *last = true;
    }
    turning
}

/// Walk the load points `points` from `state` as [`run_history`] does, pushing a record per
/// step onto `records` (in place of the earlier ones without [`RunOptions::keep_records`]; the
/// observer sees each, and the state at each turning point, [`turning_points`]), and return
/// the first failure, if any.
///
/// The spectral solver takes the steps while it can (`spectral_stretch`). Unless the
/// choice is [`SolverChoice::Spectral`], a step it fails is taken by the general solver,
/// from the last committed state ([`GeneralRun::handover`]), and so are the steps after it
/// until the spectral solver can take one again (`resumes`); [`SolverChoice::General`]
/// hands over at the first step. The driver is left at the last state the spectral solver
/// committed, and the general solver's run in the state while it holds the steps. The run
/// ends early, complete, at a turning point where the observer asks it to
/// ([`Observer::stop`]: the cycles have settled).
pub fn continue_run(
    model: &ContactModel,
    disc: &Discretisation,
    state: &mut HistoryState,
    points: &[LoadPoint],
    options: RunOptions,
    observer: &mut dyn Observer,
    records: &mut Vec<StepRecord>,
) -> Option<StepFailure> {
    let turning = turning_points(current_load(state), points);
    // The first step that changes P or the electric load of the spectral solver's state (its
    // loads never change, and that step drops it): where a spectral stretch must end.
    let first_move = state.driver.as_ref().and_then(|driver| {
        points
            .iter()
            .position(|&p| moves_the_punch_from(model, driver, p))
    });
    let mut next = 0;
    let mut recall = Recall::new(options.slip.accelerations.general_recall);
    if options.solver == SolverChoice::General
        && let (Some(driver), None) = (&state.driver, &state.general)
    {
        state.general = Some(GeneralRun::handover(
            model,
            driver,
            options.general_element_size,
            &mut recall,
        ));
    }
    while next < points.len() {
        let point = points[next];
        if moves_the_punch(model, state, point) {
            if options.solver == SolverChoice::Spectral {
                return Some(StepFailure {
                    step: point.step,
                    t: point.t,
                    q: point.q,
                    regime: Regime::Stick,
                    failure: SolveFailure::NoAdmissibleState {
                        reason: "the spectral solver holds P and the electric load fixed; a \
                                 history that changes them needs the general solver"
                            .into(),
                    },
                });
            }
            // The spectral solver's memory cannot describe a past with another normal or
            // electric load: the general solver takes this step and every later one.
            general_from_here(model, state, options.general_element_size, &mut recall);
        }
        // The step's load before it, for the turning points (`Turnings::step`).
        let mut before = current_load(state);
        let (mut run, step) = match (state.general.take(), &mut state.driver) {
            (Some(mut run), _) => {
                let step = run.step(model, point, &mut recall);
                (run, step)
            }
            (None, None) => unreachable!("a run state holds a driver or a general run"),
            (None, Some(driver)) => {
                // The spectral stretch ends before the first step that moves the punch.
                let end = first_move.unwrap_or(points.len());
                let stretch = spectral_stretch(
                    model,
                    disc,
                    (driver, &mut state.turnings),
                    (&points[next..end], &turning[next..end]),
                    options,
                    (observer, &mut recall),
                    records,
                );
                let Some(stop) = stretch else {
                    if end == points.len() || observer.stop() {
                        return None;
                    }
                    next = end;
                    continue;
                };
                next += stop.at;
                before = driver.state.tangential_load;
                if options.solver == SolverChoice::Spectral {
                    return Some(stop.failure);
                }
                observer.on_handover(&stop.failure);
                match stop.taken {
                    Some((run, record)) => (run, Ok(record)),
                    None => {
                        let mut run = GeneralRun::handover(
                            model,
                            driver,
                            options.general_element_size,
                            &mut recall,
                        );
                        let step = run.step(model, points[next], &mut recall);
                        (run, step)
                    }
                }
            }
        };
        let record = match step {
            Ok(record) => record,
            Err(failure) => {
                // The run holds the state after the last accepted step (a failed step
                // leaves it as it was).
                state.general = Some(run);
                return Some(failure);
            }
        };
        let mut record = record;
        let point = points[next];
        let continued = state.turnings.step(before, point.q);
        let back = match (options.solver, &mut state.driver) {
            (SolverChoice::Auto, Some(driver)) => resumes(
                model,
                disc,
                driver,
                &mut run,
                (points[next], &record, turning[next]),
                options.slip,
            )
            .map(|increments| (increments, driver.displacement)),
            _ => None,
        };
        if let Some((increments, displacement)) = &back {
            // The general steps since the handover add up to the spectral solver's increments
            // over them: this step takes the rest (see `resumes`).
            let [normal, electric] = run.works_before_this_step();
            record.displacement = *displacement;
            record.normal_work = increments.normal_work - normal;
            record.electric_work = increments.electric_work - electric;
        }
        let mut spectral_again = back.is_some();
        if let (false, Some(base), SolverChoice::Auto) = (spectral_again, continued, options.solver)
            && state.driver.is_some()
            && let Some(driver) = continues(
                model,
                disc,
                (*base, &[]),
                &run,
                (point, &record, before),
                options.slip,
            )
        {
            // The step's δ is the spectral solver's, as after `resumes`; its works and
            // dissipation are the general solver's step's.
            record.displacement = driver.displacement;
            state.driver = Some(driver);
            spectral_again = true;
        }
        if !spectral_again
            && turning[next]
            && options.solver == SolverChoice::Auto
            && state.driver.is_some()
            && record.zones.stick == 1
            && let Some((base, targets)) = state.turnings.replay()
        {
            // The general solver took this turning point: the spectral solver's state
            // rebuilt from the reduced history (`Turnings::replay`), if it agrees.
            let replayed = continues(
                model,
                disc,
                (base.clone(), &targets),
                &run,
                (point, &record, before),
                options.slip,
            );
            state.turnings.replayed(replayed.is_some());
            if let Some(mut driver) = replayed {
                // δ goes on from the general solver's: the loops the replay leaves out can
                // have moved the punch on a coupled contact (Masing's rule is not exact there).
                driver.displacement = record.displacement;
                state.driver = Some(driver);
                spectral_again = true;
            }
        }
        observer.on_step(&record, StateView::General(run.solver(), &run.state));
        keep(records, record, options.keep_records);
        if !spectral_again {
            state.general = Some(run);
        }
        if turning[next] {
            let spectral = if spectral_again {
                state.driver.as_ref()
            } else {
                None
            };
            state.turnings.end_phase(point.q, spectral);
            observer.on_checkpoint(records.last().expect("just pushed"), state.view());
            if observer.stop() {
                return None;
            }
        }
        next += 1;
    }
    None
}

/// Give the rest of the run to the general solver: hand the driver's state over (elements of
/// at most `inner`·a) unless the general solver holds the steps already, and drop the
/// spectral driver, whose memory cannot describe the past that follows.
fn general_from_here(
    model: &ContactModel,
    state: &mut HistoryState,
    inner: f64,
    recall: &mut Recall,
) {
    if let (None, Some(driver)) = (&state.general, &state.driver) {
        state.general = Some(GeneralRun::handover(model, driver, inner, recall));
    }
    state.driver = None;
}

/// Add `record` to `records`: after every earlier one when `all`, in place of them otherwise
/// ([`RunOptions::keep_records`]).
pub(super) fn keep(records: &mut Vec<StepRecord>, record: StepRecord, all: bool) {
    if !all {
        records.clear();
    }
    records.push(record);
}

/// Whether the step to `point` changes the normal or the electric load or the bulk stress of
/// the state.
fn moves_the_punch(model: &ContactModel, state: &HistoryState, point: LoadPoint) -> bool {
    match (&state.general, &state.driver) {
        (Some(run), _) => point.punch.is_some_and(|punch| {
            punch
                != PunchLoads::of(run.state.loads.normal, run.state.loads.electric)
                    .with_bulk_stress(run.state.loads.bulk_stress)
        }),
        (None, Some(driver)) => moves_the_punch_from(model, driver, point),
        (None, None) => unreachable!("a run state holds a driver or a general run"),
    }
}

/// Whether the step to `point` changes the normal or the electric load of the spectral
/// solver's state (whose electric load is the model's).
fn moves_the_punch_from(model: &ContactModel, driver: &DriverState, point: LoadPoint) -> bool {
    point.punch.is_some_and(|punch| {
        let electric = super::general::loads_of(model, 0.0, 0.0).electric;
        punch != PunchLoads::of(driver.state.normal_load, electric)
    })
}

/// The prescribed tangential value of the state's last step: Q, or δ under a prescribed
/// displacement.
fn current_load(state: &HistoryState) -> f64 {
    match &state.general {
        Some(run) if run.control == Control::Displacement => run.displacement(),
        Some(run) => run.state.loads.tangential,
        None => {
            state
                .driver
                .as_ref()
                .expect("a run state holds a driver or a general run")
                .state
                .tangential_load
        }
    }
}

/// Whether the spectral solver takes the state of a general step back: only within the phase
/// of the handover (its memory is the driver's), and only when it solves the step to its
/// tolerance, with the same zone structure and the contact and stick ends within two elements
/// of the general solver's ([`agrees`]). The driver then commits that state as one step from
/// its last state, with its own increments: within a phase the spectral state, and δ at a
/// point that sticks, depend on the memory and Q only, so δ goes on from the spectral
/// solver's value and the general steps' discretisation error in δ does not accumulate over
/// cycles. Returns those increments from the state of the handover (δ, and the works of P and
/// of the electric load, which are differences of state functions too).
///
/// Tried after 2, 4, 8, … general steps of the phase and at the step that ends the phase
/// (`last_of_phase`, a turning point of the load), after which the spectral solver's memory no
/// longer holds ([`GeneralRun::resume_due`]).
fn resumes(
    model: &ContactModel,
    disc: &Discretisation,
    driver: &mut DriverState,
    run: &mut GeneralRun,
    (point, last, last_of_phase): (LoadPoint, &StepRecord, bool),
    options: SlipOptions,
) -> Option<StepIncrements> {
    let same_phase =
        run.phases_begun == 0 || (run.phases_begun == 1 && run.first_began_at_handover);
    if !same_phase || last.regime.slip_sign().is_none() {
        return None;
    }
    if !run.resume_due(last_of_phase) {
        return None;
    }
    let options = take_back_options(options);
    match try_step(model, disc, driver, point, options) {
        Ok(Tried::Slip(trial)) if agrees(run, last, &trial.record(driver)) => {
            Some(commit_unobserved(model, driver, trial))
        }
        _ => {
            run.resume_failed();
            None
        }
    }
}

/// Whether the spectral solver takes the state of a general step back from a turning state it
/// kept ([`Turnings`]): `base`, the spectral driver's state at the end of a phase, stepped
/// through the turning points `targets` (none when the step closed the loops after `base`, so
/// that it continues that phase, Masing's rule; those remembered after it for a replay) and
/// on to the step's load, in steps no longer than the history's (a continued phase's each
/// within the budget of a take-back; a replay's within a step's own, as a replay is tried at
/// most once in 2ⁿ turning points, and its first loading to the largest loads needs more). The
/// result must agree with the general solver's record of the step ([`agrees`]) and, since a
/// kept state can miss what the loops left out did to the memory (Masing's rule is exact
/// only on an uncoupled contact), with its state's shear tractions ([`TAKE_BACK_SHEAR`]).
/// Returns the driver at the step, numbered as the step's phase.
///
/// [`Turnings`]: super::Turnings
fn continues(
    model: &ContactModel,
    disc: &Discretisation,
    (mut driver, targets): (DriverState, &[f64]),
    run: &GeneralRun,
    (point, general, before): (LoadPoint, &StepRecord, f64),
    options: SlipOptions,
) -> Option<DriverState> {
    if run.control != Control::Load {
        return None;
    }
    let options = if targets.is_empty() {
        take_back_options(options)
    } else {
        options
    };
    let limit = model.friction * driver.state.normal_load;
    let longest = (point.q - before).abs().max(1e-3 * limit);
    let stretches = targets.iter().chain([&point.q]);
    for (s, &to) in stretches.enumerate() {
        let from = driver.state.tangential_load;
        let parts = ((to - from).abs() / longest).ceil().max(1.0) as usize;
        for k in 1..=parts {
            let q = from + (to - from) * k as f64 / parts as f64;
            let part = LoadPoint { q, ..point };
            let last = s == targets.len();
            if last && k == 1 {
                // The phase under way is the step's.
                driver.phase = general
                    .phase
                    .saturating_sub(usize::from(begins_phase(model, &driver, part)));
            }
            let tried = try_step(model, disc, &driver, part, options);
            let Ok(Tried::Slip(trial)) = tried else {
                return None;
            };
            if last && k == parts && !agrees(run, general, &trial.record(&driver)) {
                return None;
            }
            commit_unobserved(model, &mut driver, trial);
        }
    }
    // The ends agree; so must the shear where the contact sticks, which holds the memory.
    let [_, shear] = run.solver().traction_distance(&driver.state, &run.state);
    (shear <= TAKE_BACK_SHEAR).then_some(driver)
}

/// The largest distance of the shear tractions ([`Solver::traction_distance`], the L1 norm of
/// the element means' difference relative to ηP) at which a state rebuilt from a kept turning
/// state ([`continues`]) is taken back. On the default contact's first 400 random reversals
/// (`random.seed(7)`), the states that went on as the general solver's did were at 2.7e−4 to
/// 1.5e−3, a replay whose stick zone held another memory (its ends within two elements; six
/// phases later its stick end was 0.21 a from the general-only run's) at 0.11; on the uncoupled
/// contact of the tests, exact, 4.6e−5 and 2.9e−4.
///
/// [`Solver::traction_distance`]: crate::contact::general::Solver::traction_distance
pub(super) const TAKE_BACK_SHEAR: f64 = 5e-3;

/// Commit `trial` to `driver` and finish the step with its increments, which no observer sees
/// (a take-back: the general solver's record stands for the step); returns the increments.
fn commit_unobserved(
    model: &ContactModel,
    driver: &mut DriverState,
    trial: Box<Trial>,
) -> StepIncrements {
    let solved = driver.commit(*trial);
    let increments = solved
        .known_increments()
        .unwrap_or_else(|| StepIncrements::compute(model, &solved.increment_inputs(driver)));
    finish_step(driver, solved, increments, &mut NoObserver);
    increments
}

/// `options` with a step's evaluations bounded by [`TAKE_BACK_EVALUATIONS`].
fn take_back_options(options: SlipOptions) -> SlipOptions {
    SlipOptions {
        step_evaluations: Some(
            options
                .step_evaluations
                .map_or(TAKE_BACK_EVALUATIONS, |n| n.min(TAKE_BACK_EVALUATIONS)),
        ),
        ..options
    }
}

/// The most residual evaluations of a try to take the state back ([`resumes`]), in place of a
/// step's [`SlipOptions::step_evaluations`] (600 under `auto`). A try is optional: the general
/// solver holds the step either way, so a try that would need more only leaves the state with
/// it a few steps longer, while a try that fails costs its whole budget. On the failure map's
/// PZT-4 runs at the potential of Γ = 6e−7 C/m, η = 0.05, variable amplitude (788 steps):
/// 77.0 s and 67 handovers with 600 evaluations a try and every lost take-back waited for 4
/// steps, 56.6 s and 40 with the waits doubled ([`GeneralRun::take_back_lost`]), 20.5 s and 11
/// with this bound too; η = 0.1, non-zero mean (1,972 steps): 38.7 s and 74 handovers, then
/// 17.5 s and 16 with both (13.6 s under `general` alone). The default run takes the same
/// steps with either bound.
const TAKE_BACK_EVALUATIONS: usize = 100;

/// Where the spectral solver stopped: the index of the step it did not take, why, and the
/// general solver's run and record of that step if its check took it already.
struct Stop {
    at: usize,
    failure: StepFailure,
    taken: Option<(GeneralRun, StepRecord)>,
}

/// The spectral solver's steps from `driver` over `points`, pushing a record per step onto
/// `records`; where it stopped, if it did (the driver is then at the last accepted step).
/// Under `check_phases` the general solver checks the first step of each phase and each
/// turning point as well, and the step stops the stretch when the two disagree
/// ([`contradicted`], [`turning_checked`]); the checks run beside the steps that follow them
/// (`super::checks`).
///
/// [`contradicted`]: super::checks::contradicted
/// [`turning_checked`]: super::checks::turning_checked
///
/// Pipelined on two threads: a step's increments (δ, dissipation, δn: a third of the work of
/// a step) need only its two states, so they are computed on a worker thread while the next
/// step is solved; steps are finished in order, so records, δ and the observer's calls are
/// those of the sequential [`advance`]. One worker for the run (a thread spawned per step
/// cost its stack mappings and wake-ups at every step). A step whose increments are known (a
/// recalled step, [`SolvedStep::known_increments`]) sends the worker nothing.
///
/// [`advance`]: super::advance
fn spectral_stretch(
    model: &ContactModel,
    disc: &Discretisation,
    (driver, turnings): (&mut DriverState, &mut Turnings),
    (points, turning): (&[LoadPoint], &[bool]),
    options: RunOptions,
    (observer, recall): (&mut dyn Observer, &mut Recall),
    records: &mut Vec<StepRecord>,
) -> Option<Stop> {
    // The stretch begins right after a take-back (`resumes`: the last record is the
    // general solver's): a handover at its first step is a take-back lost.
    let after_take_back = options.solver == SolverChoice::Auto
        && records
            .last()
            .is_some_and(|r| r.solver == SolverKind::General);
    let mut sink = Sink {
        observer,
        turnings,
        records,
        keep_records: options.keep_records,
    };
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
        // The step committed last, whose increments are still to come: its index, load before
        // it and state.
        let mut pending: Option<(usize, f64, Box<SolvedStep>)> = None;
        let finish = |pending: Option<(usize, f64, Box<SolvedStep>)>,
                      driver: &mut DriverState,
                      held: &mut Held| {
            if let Some((at, from, solved)) = pending {
                let increments = solved.known_increments().unwrap_or_else(|| {
                    results
                        .recv()
                        .expect("the increments of a step do not panic")
                });
                let record = settle_step(driver, &solved, increments);
                let to = solved.inputs.new.tangential_load;
                held.step((at, from, to), record, StepState::Slip(solved));
            }
        };
        let mut checks = Checks::new(scope, model, options, recall);
        let mut held = Held::default();
        // What the checks' outcome leaves of the stretch: `None` to go on.
        let settle = |found: Option<Contradiction>,
                      driver: &mut DriverState,
                      held: &mut Held,
                      sink: &mut Sink|
         -> Option<Option<Stop>> {
            // None contradicted (yet): the steps are shown as they are verified.
            let Contradiction {
                at,
                handover,
                before,
            } = found?;
            if let Shown::Stop = held.show(at, driver, sink) {
                return Some(None);
            }
            held.drop_from(at);
            if let Some(before) = before {
                *driver = *before;
            }
            let (failure, mut taken) = *handover;
            if at == 0 && after_take_back {
                taken.0.take_back_lost(driver.take_back_lost());
            }
            Some(Some(Stop {
                at,
                failure,
                taken: Some(taken),
            }))
        };
        for (k, &point) in points.iter().enumerate() {
            // The first step of a phase and every turning point are checked by the general
            // solver from the state before them (with the previous step finished: the general
            // run starts from its δ).
            let check = options.check_phases && begins_phase(model, driver, point);
            let check_turning = options.check_phases && turning[k];
            if check || check_turning {
                finish(pending.take(), driver, &mut held);
            }
            let before = driver.state.tangential_load;
            let tried = try_step(model, disc, driver, point, options.slip);
            finish(pending.take(), driver, &mut held);
            if let Ok(Tried::Slip(trial)) = &tried {
                if check {
                    let claim = Claim::PhaseStart(trial.record(driver));
                    checks.start(k, driver, point, claim);
                }
                if check_turning {
                    let claim = Claim::Turning(trial.solved.state.clone());
                    checks.start(k, driver, point, claim);
                }
            }
            if let Some(end) = settle(checks.resolve(OPEN_CHECKS), driver, &mut held, &mut sink) {
                return end;
            }
            match tried {
                Ok(Tried::Hold(regime)) => {
                    let record = hold_record(driver, point, regime);
                    let state = StepState::Hold(Box::new(driver.state.clone()));
                    held.step((k, before, point.q), record, state);
                }
                Ok(Tried::Slip(trial)) => {
                    checks.committing(k, driver);
                    let solved = Box::new(driver.commit(*trial));
                    if solved.known_increments().is_none() {
                        jobs.send(solved.increment_inputs(driver))
                            .expect("the increments worker runs until the steps end");
                    }
                    pending = Some((k, before, solved));
                }
                Err(failure) => {
                    if let Some(end) = settle(checks.resolve(0), driver, &mut held, &mut sink) {
                        return end;
                    }
                    if let Shown::Stop = held.show(usize::MAX, driver, &mut sink) {
                        return None;
                    }
                    let taken = (k == 0 && after_take_back)
                        .then(|| {
                            let lost_before = driver.take_back_lost();
                            let recall = checks.recall();
                            take_back_lost(model, driver, (point, options, lost_before), recall)
                        })
                        .flatten();
                    return Some(Stop {
                        at: k,
                        failure,
                        taken,
                    });
                }
            }
            if turning[k] {
                finish(pending.take(), driver, &mut held);
                let below = checks.verified_below();
                if let Shown::Stop = held.turning((k, point.q, below), driver, &mut sink) {
                    return None;
                }
            } else if let Shown::Stop = held.show(checks.verified_below(), driver, &mut sink) {
                return None;
            }
        }
        finish(pending.take(), driver, &mut held);
        if let Some(end) = settle(checks.resolve(0), driver, &mut held, &mut sink) {
            return end;
        }
        match held.show(usize::MAX, driver, &mut sink) {
            Shown::Done | Shown::Stop => None,
        }
    })
}

/// The most checks open while the spectral solver goes on past them (`super::checks`): it
/// waits for the oldest beyond that, which bounds the steps held for the observer and the
/// driver states kept to go back to. On the first 200 of the 1,000 random reversals
/// (`benches/scenarios/random_variable_amplitude_1000.json`), with 1, 2, 4 and any number
/// open: 8.4, 7.4, 6.7 and 6.6 s; the default run 0.31, 0.30, 0.30 and 0.30 s (0.35 s when
/// it waits for each check at once).
const OPEN_CHECKS: usize = 4;

/// The general solver's run and record of the step at `point`, which the spectral solver
/// failed right after it took the state back (`resumes`), handed over from the driver's state
/// with its next try postponed ([`GeneralRun::take_back_lost`], after `lost_before` take-backs
/// lost earlier in the phase); `None` when the general solver cannot take the step either (the
/// caller's handover then meets that failure).
fn take_back_lost(
    model: &ContactModel,
    driver: &DriverState,
    (point, options, lost_before): (LoadPoint, RunOptions, usize),
    recall: &mut Recall,
) -> Option<(GeneralRun, StepRecord)> {
    let mut run = GeneralRun::handover(model, driver, options.general_element_size, recall);
    let record = run.step(model, point, recall).ok()?;
    run.take_back_lost(lost_before);
    Some((run, record))
}

/// Whether the general solver's record of a step and the spectral solver's describe one state
/// ([`disagreement`] finds nothing).
fn agrees(run: &GeneralRun, general: &StepRecord, spectral: &StepRecord) -> bool {
    disagreement(run, general, spectral).is_none()
}

/// Whether the step at `point` begins a phase from the driver's state.
fn begins_phase(model: &ContactModel, driver: &DriverState, point: LoadPoint) -> bool {
    let limit = model.friction * driver.state.normal_load;
    let regime = next_regime(point.q - driver.state.tangential_load, 1e-12 * limit);
    matches!(phase_event(driver.phase_sign, regime), PhaseEvent::Begin(_))
}

#[cfg(test)]
mod tests;
