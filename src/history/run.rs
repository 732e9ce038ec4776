//! The loop over a load history: [`run_history`] from the normal loading and [`continue_run`]
//! from any driver state, each solving a step while the previous step's increments are
//! computed on a second thread; the run's result ([`HistoryRun`]) and failure
//! ([`HistoryFailure`]).

use crate::contact::ContactModel;
use crate::contact::normal::NormalLoading;
use crate::contact::pressure::Discretisation;
use crate::contact::tangential::SlipOptions;

use super::driver::{
    DriverState, Solved, SolvedStep, finish_step, hold_record, record, solve_step,
};
use super::general::{GeneralRun, RunOptions, SolverChoice};
use super::increments::{IncrementInputs, StepIncrements};
use super::load::{LoadHistory, LoadPoint};
use super::record::{Observer, StateView, StepFailure, StepRecord};
use super::regime::Regime;

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
    options: RunOptions,
    observer: &mut dyn Observer,
) -> Result<HistoryRun, Box<HistoryFailure>> {
    let mut driver = DriverState::after_normal_loading(normal);
    let t0 = history.points.first().map_or(0.0, |p| p.0);
    let mut records = vec![record(0, t0, &driver, Regime::NormalLoading, None)];
    observer.on_step(&records[0], StateView::Spectral(&driver.state));
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
/// step onto `records` (the observer sees each), and return the first failure, if any.
///
/// The spectral solver takes the steps while it can ([`spectral_stretch`]). Unless the
/// choice is [`SolverChoice::Spectral`], a step it fails is taken by the general solver,
/// from the last committed state ([`GeneralRun::handover`]), and so are the steps after it
/// until the spectral solver can take one again ([`resumes`]); [`SolverChoice::General`]
/// hands over at the first step. The driver is left at the last state the spectral solver
/// committed.
pub fn continue_run(
    model: &ContactModel,
    disc: &Discretisation,
    driver: &mut DriverState,
    points: &[LoadPoint],
    options: RunOptions,
    observer: &mut dyn Observer,
    records: &mut Vec<StepRecord>,
) -> Option<StepFailure> {
    let mut next = 0;
    let mut general =
        (options.solver == SolverChoice::General).then(|| GeneralRun::handover(model, driver));
    while next < points.len() {
        let Some(run) = general.as_mut() else {
            let (taken, failure) = spectral_stretch(
                model,
                disc,
                driver,
                &points[next..],
                options.slip,
                observer,
                records,
            )?;
            next += taken;
            if options.solver == SolverChoice::Spectral {
                return Some(failure);
            }
            observer.on_handover(&failure);
            general = Some(GeneralRun::handover(model, driver));
            continue;
        };
        let point = points[next];
        let record = match run.step(model, point) {
            Ok(record) => record,
            Err(failure) => return Some(failure),
        };
        observer.on_step(&record, StateView::General(run.solver(), &run.state));
        next += 1;
        if options.solver == SolverChoice::Auto
            && resumes(model, disc, driver, run, (point, &record), options.slip)
        {
            general = None;
        }
        records.push(record);
    }
    None
}

/// Whether the spectral solver takes the state of a general step back: only within the phase
/// of the handover (its memory is the driver's), and only when it solves the step to its
/// tolerance, with the same zone structure and the contact and stick ends within the element
/// size there. The driver then commits that state, with the general run's δ.
fn resumes(
    model: &ContactModel,
    disc: &Discretisation,
    driver: &mut DriverState,
    run: &GeneralRun,
    (point, last): (LoadPoint, &StepRecord),
    options: SlipOptions,
) -> bool {
    let same_phase =
        run.phases_begun == 0 || (run.phases_begun == 1 && run.first_began_at_handover);
    if !same_phase || last.regime.slip_sign().is_none() {
        return false;
    }
    let mut trial = driver.clone();
    let Ok(Solved::Slip(_)) = solve_step(model, disc, &mut trial, point, options) else {
        return false;
    };
    let spectral = record(point.step, point.t, &trial, last.regime, None);
    if spectral.zones != last.zones || spectral.phase != last.phase {
        return false;
    }
    let resolution = |x: f64| 2.0 * run.state.mesh.width_at(x);
    let agree = |a: f64, b: f64| (a - b).abs() <= resolution(b);
    let (lo, hi) = (
        -last.eccentricity - last.half_width,
        -last.eccentricity + last.half_width,
    );
    let (slo, shi) = (
        -spectral.eccentricity - spectral.half_width,
        -spectral.eccentricity + spectral.half_width,
    );
    if !(agree(slo, lo)
        && agree(shi, hi)
        && agree(spectral.stick_lo, last.stick_lo)
        && agree(spectral.stick_hi, last.stick_hi))
    {
        return false;
    }
    trial.displacement = run.displacement();
    trial.anchor_ux = None;
    trial.approach = None;
    *driver = trial;
    true
}

/// The spectral solver's steps from `driver` over `points`, pushing a record per step onto
/// `records`; the index and failure of the first step it fails, if any (the driver is then at
/// the last accepted step).
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
    driver: &mut DriverState,
    points: &[LoadPoint],
    options: SlipOptions,
    observer: &mut dyn Observer,
    records: &mut Vec<StepRecord>,
) -> Option<(usize, StepFailure)> {
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
        for (k, &point) in points.iter().enumerate() {
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
                Err(failure) => return Some((k, failure)),
            }
        }
        finish(pending.take(), driver, records, observer);
        None
    })
}
