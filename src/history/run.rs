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
use super::increments::{IncrementInputs, StepIncrements};
use super::load::{LoadHistory, LoadPoint};
use super::record::{Observer, StepFailure, StepRecord};
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
///
/// [`advance`]: super::advance
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
