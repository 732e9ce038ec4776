//! One run of a scenario: [`solve`] computes everything and writes nothing; [`run`] also writes
//! the output folder that `fretsim run` writes (claimed before the solve, swapped in at the end).

use std::path::{Path, PathBuf};

use crate::analysis::{CycleAnalysis, CycleRow};
use crate::contact::SurfacePoint;
use crate::contact::normal::NormalLoading;
use crate::history::NormalEnd;
use crate::contact::pressure::Discretisation;
use crate::contact::tangential::SlipOptions;
use crate::error::Error;
use crate::history::HistoryStateView;
use crate::history::{RunOptions, SolvedState, StateView, StepRecord};
use crate::io::checkpoint::{Kept, Resume, RunSink, write_records, write_state};
use crate::contact::general::PointLogs;
use crate::fatigue::{FatigueAnalysis, FatigueProfile, step_samples};
use crate::io::csv::{StepsCsv, cycles_table, fields_table};
use crate::io::fatigue::{FatigueSummary, fatigue_plot, fatigue_table};
use crate::io::folder::{Protected, RunFolder};
use crate::io::history_plots::{PlotWindow, history_plots};
use crate::io::plots::{
    FamilyMember, PlotScales, ZoneEnds, family_plots, index_html, normal_loading_plots,
};
use crate::io::png::plot_files;
use crate::io::subsurface::{SubsurfaceMap, SubsurfaceOutput, subsurface_plots, subsurface_table};
use crate::io::summary::{
    Handover, HandoverLog, RecordTally, Resolved, SnapshotSummary, Summary, derived,
    history_summary, normal_summary, solver_statistics,
};
use crate::scenario::{Scenario, TurningFields};

/// What a run produced.
#[derive(Debug)]
pub struct RunResult {
    /// Output folder.
    pub out_dir: PathBuf,
    /// What was solved and written; a history that stopped part-way has its failure in
    /// [`Solution::failure`].
    pub solution: Solution,
}

/// Everything a run computes, before anything is written: what [`solve`] returns and what
/// the output files are made of.
#[derive(Debug)]
pub struct Solution {
    /// The summary (`summary.json`).
    pub summary: Summary,
    /// The sampled fields: the end of normal loading, then one set per snapshot time reached.
    pub fields: Vec<FieldSet>,
    /// The fields at the turning points that `output.turning_point_fields` asks for and at
    /// the last step.
    pub turning_fields: Vec<FieldSet>,
    /// One record per accepted step (step 0 is the end of normal loading) from [`solve`];
    /// none from [`run()`] and [`run_partial`], which write them into `steps.csv` as they are
    /// taken (an observer given to [`run_partial`] sees each).
    pub records: Vec<crate::history::StepRecord>,
    /// The cycles of the history.
    pub cycles: Vec<CycleRow>,
    /// The fretting-fatigue indicators of the last complete cycle ([`crate::fatigue`]).
    pub fatigue: Option<FatigueProfile>,
    /// The solver failure that stopped the history part-way, if any.
    pub failure: Option<Error>,
    /// The state at the last accepted step of a history that stopped part-way (written into
    /// `failure.json`).
    pub failure_state: Option<crate::history::HistoryState>,
    /// The last accepted step.
    pub(crate) last: Option<StepRecord>,
    /// The steps the history plots draw.
    pub(crate) plots: Option<PlotWindow>,
    /// The most step records the run held at once besides [`Solution::records`] (the plots'
    /// steps and those of the phase under way not yet in a checkpoint).
    pub records_held: usize,
}

/// Sample points for field output: the contact and a margin of one half-width each side,
/// never exactly at the contact ends (where g and Dx0 are singular for a conducting punch).
pub fn field_points(centre: f64, half_width: f64, count: usize) -> Vec<f64> {
    (0..count)
        .map(|i| centre + 2.0 * half_width * ((2 * i + 1) as f64 - count as f64) / count as f64)
        .collect()
}

/// Solve a validated scenario and write its outputs into `out_dir`, which must be new or a
/// previous fretsim output ([`RunFolder::claim`]).
pub fn run(scenario: &Scenario, out_dir: &Path) -> Result<RunResult, Error> {
    let mut result = run_partial(scenario, out_dir, &mut crate::history::NoObserver)?;
    match result.solution.failure.take() {
        None => Ok(result),
        Some(failure) => Err(failure),
    }
}

/// Sampled surface fields of one instant: a field file and a curve of the plots.
#[derive(Debug, Clone)]
pub struct FieldSet {
    /// File stem under `fields/` (`normal_loading`, `t_2.000000`).
    pub stem: String,
    /// Legend label.
    pub label: String,
    /// The samples.
    pub points: Vec<SurfacePoint>,
    /// Where the contact and the stick zone end (marked on the plots).
    pub ends: ZoneEnds,
    /// The fields below the surface at the same instant (`output.subsurface`), written to
    /// `subsurface/<stem>.csv`.
    pub subsurface: Option<SubsurfaceMap>,
}

/// Keeps, while the history runs, the states that the field files need: the turning points
/// (the last step of each phase) that `output.turning_point_fields` asks for, the last step,
/// and the steps at the snapshot times. A long run keeps a few states, not one per phase.
/// With a checkpoint sink, it also writes a checkpoint at every turning point of the load
/// ([`crate::io::checkpoint`]).
pub(crate) struct Snapshots<'a> {
    inner: &'a mut dyn crate::history::Observer,
    scenario: &'a Scenario,
    kept: Kept,
    /// Which turning points are kept (`output.turning_point_fields`).
    turning: TurningFields,
    /// Where checkpoints go, with the records not yet saved, the number saved, and the first
    /// error in saving one.
    checkpoints: Option<&'a mut dyn RunSink>,
    unsaved: Vec<StepRecord>,
    /// What the outputs take from the records.
    digest: Digest,
    /// The most records held at once by the digest and the checkpoints' unsaved records.
    held: usize,
    saved: usize,
    error: Option<Error>,
    /// Checkpoints written by this process.
    written: usize,
    /// Whether the run ended where its cycles had settled (`numerics.stop_when_settled`).
    stopped: std::cell::Cell<bool>,
    /// The logarithms of the fatigue grid on the general solver's last mesh (a speed-up:
    /// the samples agree with those without it to round-off).
    point_logs: PointLogs,
}

impl crate::history::Observer for Snapshots<'_> {
    fn on_step(&mut self, record: &crate::history::StepRecord, state: StateView<'_>) {
        let kept = &mut self.kept;
        if let Some(fatigue) = &mut kept.fatigue {
            let before = kept.previous.as_ref().map(|(_, s)| s.view());
            let logs = Some(&mut self.point_logs);
            let samples = step_samples(&self.scenario.model, fatigue.grid(), before, state, logs);
            fatigue.push(record, samples);
        }
        if let Some((prev, prev_state)) = kept.previous.take()
            && prev.phase != record.phase
            && prev.phase > 0
        {
            match self.turning {
                TurningFields::All => kept.turning.push((prev, prev_state)),
                TurningFields::FirstAndLast if prev.phase <= 3 => {
                    kept.turning.push((prev, prev_state));
                }
                TurningFields::FirstAndLast => {
                    if kept.last.len() == 2 {
                        kept.last.remove(0);
                    }
                    kept.last.push((prev, prev_state));
                }
                TurningFields::None => {}
            }
        }
        kept.previous = Some((record.clone(), state.to_owned()));
        // The last step at a snapshot time wins (a ramp to a non-zero first point is solved
        // in several steps at the same time).
        let times = &self.scenario.snapshots;
        for (t, slot) in times.iter().zip(kept.at_times.iter_mut()) {
            if (record.t - t).abs() <= self.scenario.time_tolerance {
                *slot = Some((record.clone(), state.to_owned()));
            }
        }
        if self.checkpoints.is_some() {
            self.unsaved.push(record.clone());
        }
        self.digest.push(record);
        self.held = self
            .held
            .max(self.digest.records_held() + self.unsaved.len());
        self.inner.on_step(record, state);
    }

    fn on_checkpoint(&mut self, last: &StepRecord, state: HistoryStateView<'_>) {
        let Some(sink) = self.checkpoints.as_mut() else {
            return;
        };
        if self.error.is_some() {
            return;
        }
        let records = write_records(&self.unsaved);
        let saved = self.saved + self.unsaved.len();
        let bytes = write_state(self.scenario, last.step, saved, &self.kept, state);
        match sink.save(&bytes, &records) {
            Ok(()) => {
                self.saved = saved;
                self.unsaved.clear();
            }
            Err(e) => self.error = Some(e),
        }
        self.written += 1;
        crate::io::folder::pause_point(&format!("checkpoint {}", self.written));
        self.inner.on_checkpoint(last, state);
    }

    fn on_phase(&mut self, phase: usize, memory: &crate::contact::memory::Memory) {
        self.inner.on_phase(phase, memory);
    }

    fn stop(&self) -> bool {
        let numerics = &self.scenario.raw.numerics;
        if numerics.stop_when_settled && self.digest.cycles.settled(numerics.cycle_tolerance) {
            self.stopped.set(true);
            return true;
        }
        self.inner.stop()
    }

    fn on_handover(&mut self, failure: &crate::history::StepFailure) {
        self.kept.handovers.push(Handover {
            step: failure.step,
            t: failure.t,
            q: failure.q,
            reason: failure.failure.to_string(),
        });
        self.inner.on_handover(failure);
    }
}

/// What the outputs take from the step records, gathered as the records arrive
/// ([`Digest::push`] each in order, step 0 first): the summary's counts and turning points
/// ([`RecordTally`]), the cycles ([`CycleAnalysis`]), the steps the history plots draw
/// ([`PlotWindow`]) and, in a written run, the rows of `steps.csv`. Apart from a row per cycle,
/// it holds a bounded number of records however long the history.
pub(crate) struct Digest {
    tally: RecordTally,
    cycles: CycleAnalysis,
    plots: PlotWindow,
    /// `steps.csv` (its path and writer) in a written run.
    steps: Option<(PathBuf, StepsCsv<Box<dyn std::io::Write>>)>,
    /// The first error in writing `steps.csv`.
    error: Option<Error>,
}

impl Digest {
    /// A digest for a run of `scenario`, writing `steps.csv` into `steps` when given (its path
    /// and writer).
    fn new(
        scenario: &Scenario,
        steps: Option<(PathBuf, Box<dyn std::io::Write>)>,
    ) -> Result<Self, Error> {
        let q_scale = scenario.history.as_ref().map_or(0.0, |h| {
            h.points.iter().map(|p| p.1.abs()).fold(0.0, f64::max)
        });
        let steps = match steps {
            Some((path, out)) => match StepsCsv::new(
                out,
                scenario.model.friction,
                scenario
                    .history
                    .as_ref()
                    .is_some_and(|h| h.has_bulk_stress()),
            ) {
                Ok(csv) => Some((path, csv)),
                Err(source) => return Err(Error::WriteOutput { path, source }),
            },
            None => None,
        };
        Ok(Self {
            tally: RecordTally::new(SlipOptions::default().tolerance),
            cycles: CycleAnalysis::new(
                scenario
                    .history
                    .as_ref()
                    .map_or(crate::history::Control::Load, |h| h.control),
            ),
            plots: PlotWindow::new(q_scale),
            steps,
            error: None,
        })
    }

    /// Take the next record.
    pub(crate) fn push(&mut self, record: &StepRecord) {
        self.tally.push(record);
        self.cycles.push(record);
        self.plots.push(record);
        if let Some((path, csv)) = &mut self.steps
            && self.error.is_none()
            && let Err(source) = csv.push(record)
        {
            self.error = Some(Error::WriteOutput {
                path: path.clone(),
                source,
            });
        }
    }

    /// The records the digest holds now (the plots' steps; the tally's and the cycle
    /// analysis's few aside): bounded, however many it took.
    pub(crate) fn records_held(&self) -> usize {
        self.plots.kept()
    }

    /// Finish `steps.csv`; the first error in writing it.
    fn finish_steps(&mut self) -> Result<(), Error> {
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        match self.steps.take() {
            Some((path, csv)) => csv
                .finish()
                .map(drop)
                .map_err(|source| Error::WriteOutput { path, source }),
            None => Ok(()),
        }
    }
}

/// As [`run()`], but a solver failure during the history stays in the result's
/// [`Solution::failure`], beside what was written (the summary and the fields reached); each
/// accepted step is reported to `observer`. A failure of the normal loading is returned as
/// `Err` after `failure.json` is written; so is a write error.
pub fn run_partial(
    scenario: &Scenario,
    out_dir: &Path,
    observer: &mut dyn crate::history::Observer,
) -> Result<RunResult, Error> {
    let folder = RunFolder::claim(out_dir, &Protected::new(None))?;
    run_resumed(scenario, folder, None, observer)
}

/// As [`run_partial`] into a claimed folder, resuming from `resume` when given (a checkpoint that an interrupted
/// run left in the folder, [`RunFolder::claim_resuming`] and
/// [`crate::io::checkpoint::read_checkpoint`]). The run writes its checkpoints into the
/// folder's staging folder as it goes ([`crate::io::checkpoint`]).
pub fn run_resumed(
    scenario: &Scenario,
    mut folder: RunFolder,
    resume: Option<Resume>,
    observer: &mut dyn crate::history::Observer,
) -> Result<RunResult, Error> {
    crate::io::folder::pause_point("solve");
    match solve_from(scenario, observer, resume, Some(&mut folder)) {
        Ok(solution) => {
            let out_dir = write_solution(folder, scenario, &solution)?;
            Ok(RunResult { out_dir, solution })
        }
        Err(error @ Error::WriteOutput { .. }) => Err(error),
        Err(error) => {
            folder.write("failure.json", &failure_json(&error, None, None))?;
            folder.commit()?;
            Err(error)
        }
    }
}

/// Solve a validated scenario: the normal loading, then the tangential history if any, and
/// the fields and the summary made from them. Writes nothing. A failure of the normal loading
/// is an `Err`; a failure part-way through the history is returned in
/// [`Solution::failure`] beside the steps solved before it.
pub fn solve(
    scenario: &Scenario,
    observer: &mut dyn crate::history::Observer,
) -> Result<Solution, Error> {
    solve_from(scenario, observer, None, None)
}

/// [`solve`], resuming from `resume` when given, and writing checkpoints into `checkpoints`
/// when given ([`crate::io::checkpoint`]).
pub(crate) fn solve_from<'a>(
    scenario: &'a Scenario,
    observer: &'a mut dyn crate::history::Observer,
    resume: Option<Resume>,
    mut checkpoints: Option<&'a mut dyn RunSink>,
) -> Result<Solution, Error> {
    let model = &scenario.model;
    let disc = Discretisation::new(scenario.collocation_points);
    let normal = NormalEnd::solve(
        model,
        &disc,
        scenario.normal_load,
        scenario.solver,
        scenario.raw.numerics.general_element_size,
    )
    .map_err(|failure| Error::Solve {
        context: "normal loading".into(),
        failure,
    })?;
    let mut warnings: Vec<String> = normal
        .spectral()
        .and_then(|n| gap_warning(scenario, n))
        .into_iter()
        .collect();
    // The tangential history, if any; a failure keeps the steps already solved. A written run
    // (with a sink) streams its records into the digest and `steps.csv` and keeps none.
    let written = checkpoints.is_some();
    let steps_file = match (&mut checkpoints, &scenario.history) {
        (Some(sink), Some(_)) => Some(sink.create("steps.csv")?),
        _ => None,
    };
    let mut digest = Digest::new(scenario, steps_file)?;
    let mut records = Vec::new();
    let mut failure = None;
    let mut failure_state = None;
    // The end of normal loading, and the contact that places the run's grids.
    let loaded = normal.solved_state();
    let reference = reference_contact(scenario, &loaded);
    let (kept, resumed) = match resume {
        Some(Resume {
            step,
            mut records,
            snapshots,
            state,
        }) => {
            // The steps taken before the checkpoint, as the interrupted run's digest took them
            // (read back one at a time; `solve` keeps them all, as it does the new ones).
            let mut last = Vec::new();
            let saved = records
                .replay(|r| {
                    digest.push(&r);
                    if !written {
                        last.push(r);
                    } else {
                        last = vec![r];
                    }
                })?;
            (snapshots, Some((step, saved, last, state)))
        }
        None => (
            Kept {
                previous: None,
                turning: Vec::new(),
                last: Vec::new(),
                at_times: vec![None; scenario.snapshots.len()],
                handovers: HandoverLog::default(),
                fatigue: scenario.history.as_ref().filter(|_| scenario.raw.output.fatigue).map(|_| {
                    let (centre, half_width) = reference;
                    let grid = field_points(centre, half_width, scenario.raw.output.field_points);
                    FatigueAnalysis::new(grid, half_width)
                }),
            },
            None,
        ),
    };
    let saved = resumed.as_ref().map_or(0, |&(_, saved, ..)| saved);
    let mut snapshots = Snapshots {
        inner: observer,
        scenario,
        kept,
        turning: scenario.raw.output.turning_point_fields,
        checkpoints,
        unsaved: Vec::new(),
        digest,
        held: 0,
        saved,
        error: None,
        written: 0,
        stopped: std::cell::Cell::new(false),
        point_logs: PointLogs::default(),
    };
    if let Some(history) = &scenario.history {
        let options = RunOptions {
            general_element_size: scenario.raw.numerics.general_element_size,
            keep_records: !written,
            ..RunOptions::new(scenario.solver)
        };
        let run = match resumed {
            None => {
                crate::history::run_history(model, &disc, &normal, history, options, &mut snapshots)
            }
            Some((step, _, last, state)) => resume_history(
                model,
                &disc,
                history,
                (step, last, state),
                options,
                &mut snapshots,
            ),
        };
        match run {
            Ok(run) => records = run.records,
            Err(f) => {
                let f = *f;
                records = f.records;
                failure_state = Some(f.state);
                failure = Some(Error::Solve {
                    context: f.failure.to_string(),
                    failure: f.failure.failure,
                });
            }
        }
        if written {
            records.clear();
        }
    }
    if let Some(e) = snapshots.error.take() {
        return Err(e);
    }
    let stopped_when_settled = snapshots.stopped.get();
    let mut kept = snapshots.kept;
    let records_held = snapshots.held;
    let mut digest = snapshots.digest;
    digest.finish_steps()?;
    let Digest {
        tally,
        cycles,
        plots,
        ..
    } = digest;
    warnings.extend(stalled_warning(&tally));
    let tolerance = scenario.raw.numerics.cycle_tolerance;
    let (mut cycles, verdict) = cycles.finish(tolerance);
    let fatigue = kept
        .fatigue
        .take()
        .and_then(|analysis| with_local_slip(analysis, &mut cycles));
    let history_summary = scenario
        .history
        .as_ref()
        .map(|_| {
            let mut summary =
                history_summary(&tally, failure.as_ref(), &cycles, verdict, tolerance);
            summary.stopped_when_settled = stopped_when_settled;
            summary
        });
    // Sampled fields: the end of normal loading, then each snapshot time reached. A state
    // without contact (the unloaded start, a punch lifted off) on the run's reference grid.
    let sample = |state: &SolvedState| -> Vec<SurfacePoint> {
        let (centre, half_width) = match state.contact() {
            (_, 0.0) => reference,
            contact => contact,
        };
        field_points(centre, half_width, scenario.raw.output.field_points)
            .into_iter()
            .map(|x| state.surface_point(model, x))
            .collect()
    };
    // The fields below the surface at the same instants, on a grid in units of the reference
    // half-width; a state whose fields cannot be computed gets a warning instead.
    let subsurface = scenario.raw.output.subsurface.as_ref().and_then(|raw| {
        SubsurfaceOutput::new(&model.material, raw, reference.1)
            .map_err(|e| warnings.push(format!("the fields below the surface are not written: {e}")))
            .ok()
    });
    if let Some(out) = &subsurface
        && !out.has_von_mises()
    {
        warnings.push(
            "the subsurface files have no syy_Pa and von_mises_Pa (σyy needs c12, which only the \
             presets carry); the maps show the in-plane maximum shear stress instead"
                .into(),
        );
    }
    let subsurface_failures = std::cell::RefCell::new(Vec::new());
    let below = |stem: &str, state: &SolvedState| -> Option<SubsurfaceMap> {
        let out = subsurface.as_ref()?;
        out.map(state)
            .map_err(|e| {
                subsurface_failures
                    .borrow_mut()
                    .push(format!("subsurface/{stem}.csv is not written: {e}"))
            })
            .ok()
    };
    let mut fields = vec![FieldSet {
        stem: "normal_loading".into(),
        label: if scenario.normal_load > 0.0 {
            "end of normal loading".into()
        } else {
            "start (the unloaded punch)".into()
        },
        points: sample(&loaded),
        ends: zone_ends(&loaded, &normal.record(0.0)),
        subsurface: below("normal_loading", &loaded),
    }];
    let (at_snapshots, snapshot_rows) = snapshot_fields(
        scenario,
        &kept.at_times,
        &sample,
        &below,
        tally.last(),
        &mut warnings,
    );
    fields.extend(at_snapshots);
    // Turning points and the last step, unless switched off.
    let mut turning_fields = Vec::new();
    if scenario.raw.output.turning_point_fields != TurningFields::None {
        let turning = kept.turning.iter().chain(&kept.last);
        for (rec, state) in turning.chain(kept.previous.iter()) {
            let stem = format!("step_{:05}", rec.step);
            turning_fields.push(FieldSet {
                label: format!("step {}", rec.step),
                points: sample(state),
                ends: zone_ends(state, rec),
                subsurface: below(&stem, state),
                stem,
            });
        }
    }
    warnings.extend(subsurface_failures.into_inner());
    let summary = Summary {
        fretsim_version: env!("CARGO_PKG_VERSION"),
        scenario: scenario.raw.clone(),
        resolved: Resolved {
            material: model.material,
            load_history: scenario.history.clone(),
        },
        derived: derived(model, scenario.reference_load),
        normal_loading: normal_summary(model, &normal),
        history: history_summary,
        snapshots: snapshot_rows,
        solver: solver_statistics(scenario, &normal, &tally, kept.handovers),
        fatigue: fatigue
            .as_ref()
            .map(|f| FatigueSummary::of(f, model.compliance.electric.is_some())),
        warnings,
    };
    Ok(Solution {
        summary,
        fields,
        turning_fields,
        records,
        cycles,
        fatigue,
        failure,
        failure_state,
        last: tally.last().cloned(),
        plots: scenario.history.as_ref().map(|_| plots),
        records_held,
    })
}

/// The cycles' largest local slip amplitudes from `analysis` put into their rows (a cycle
/// of the analysis is a row's when their first and last steps agree), and the indicators of
/// the last row's cycle.
fn with_local_slip(analysis: FatigueAnalysis, rows: &mut [CycleRow]) -> Option<FatigueProfile> {
    let (slips, last) = analysis.finish();
    for row in rows.iter_mut() {
        row.max_local_slip = slips
            .iter()
            .find(|s| s.steps == row.steps)
            .map(|s| s.max_local_slip);
    }
    let row = rows.last()?;
    last.into_iter().rev().find(|p| p.steps == row.steps)
}

/// The rest of `history` after step `step`, from `state` after the steps `records` (all those
/// taken, or the last; [`crate::history::run_history`] from a checkpoint).
fn resume_history(
    model: &crate::contact::ContactModel,
    disc: &Discretisation,
    history: &crate::history::LoadHistory,
    (step, records, state): (usize, Vec<StepRecord>, crate::history::HistoryState),
    options: RunOptions,
    observer: &mut dyn crate::history::Observer,
) -> Result<crate::history::HistoryRun, Box<crate::history::HistoryFailure>> {
    let points: Vec<_> = history
        .load_points()
        .into_iter()
        .filter(|p| p.step > step)
        .collect();
    crate::history::run_from(model, disc, (state, records), &points, options, observer)
}

/// The contact and stick-zone ends of a state, for the marks of its field plots: the
/// spectral state's own, or the record's of an element state (its outermost contact elements
/// and its longest stick run).
fn zone_ends(state: &SolvedState, rec: &StepRecord) -> ZoneEnds {
    match state {
        SolvedState::Spectral(s) => ZoneEnds::of(s),
        SolvedState::General(..) => ZoneEnds {
            contact: (
                -rec.eccentricity - rec.half_width,
                -rec.eccentricity + rec.half_width,
            ),
            stick: Some((rec.stick_lo, rec.stick_hi)),
        },
    }
}

/// The warning for a normal-loading state that interpenetrates the punch just outside the
/// contact (a conducting punch with Γ above the charge the pressure carries).
fn gap_warning(scenario: &Scenario, normal: &NormalLoading) -> Option<String> {
    let model = &scenario.model;
    let gamma1 = model.pressure_charge(scenario.normal_load);
    let gap = model.outside_gap(&normal.state);
    (gap.min_gap < 0.0).then(|| format!(
        "the surface interpenetrates the punch just outside the contact: gap {:.3e} m at x = {:.4e} m \
         (a²/2R = {:.3e} m); Γ = {:.4e} C/m exceeds the charge carried by the pressure Γ1 = kP = {gamma1:.4e} C/m, \
         and the conducting-punch model (smooth pressure at the contact ends) then admits no state with a non-negative gap",
        gap.min_gap, gap.at, gap.scale, normal.state.charge
    ))
}

/// The warning for steps the spectral solver accepted with a residual above its tolerance.
fn stalled_warning(tally: &RecordTally) -> Option<String> {
    let solver_tolerance = SlipOptions::default().tolerance;
    let (stalled, worst) = tally.stalled();
    let worst = worst?;
    Some(format!(
        "{stalled} step(s) accepted with a stalled residual above the solver tolerance {solver_tolerance:e} \
         (largest {:.3e} at step {}, t = {} s): the iteration stopped improving below the \
         stall tolerance; see the residual column of steps.csv",
        worst.residual,
        worst.step,
        worst.t
    ))
}

/// The field sets (the surface samples of `sample`, the fields below the surface of `below`)
/// and summary rows of the snapshot times reached; a warning for each one not reached.
fn snapshot_fields(
    scenario: &Scenario,
    at_times: &[Option<(StepRecord, SolvedState)>],
    sample: &dyn Fn(&SolvedState) -> Vec<SurfacePoint>,
    below: &dyn Fn(&str, &SolvedState) -> Option<SubsurfaceMap>,
    last: Option<&StepRecord>,
    warnings: &mut Vec<String>,
) -> (Vec<FieldSet>, Vec<SnapshotSummary>) {
    let limit = scenario.model.friction * scenario.reference_load;
    let mut fields = Vec::new();
    let mut rows = Vec::new();
    for (&t, kept) in scenario.snapshots.iter().zip(at_times) {
        let stem = crate::scenario::snapshot_stem(t);
        let Some((rec, state)) = kept else {
            warnings.push(format!(
                "snapshot t = {t} s was not reached (the history stopped at t = {} s); fields/{stem}.csv is not written",
                last.map_or(f64::NAN, |r| r.t)
            ));
            continue;
        };
        fields.push(FieldSet {
            label: format!("t = {t} s, Q/(ηP) = {:.3}", rec.q / limit),
            stem: stem.clone(),
            points: sample(state),
            ends: zone_ends(state, rec),
            subsurface: below(&stem, state),
        });
        rows.push(SnapshotSummary {
            t,
            file: format!("fields/{stem}.csv"),
            step: rec.step,
            step_t: rec.t,
            q: rec.q,
            q_over_limit: rec.q / limit,
            regime: rec.regime,
            phase: rec.phase,
            half_width: rec.half_width,
            eccentricity: rec.eccentricity,
            stick_lo: rec.stick_lo,
            stick_hi: rec.stick_hi,
        });
    }
    (fields, rows)
}

/// Write a solution's files into its claimed folder and swap the folder into place.
pub(crate) fn write_solution(
    mut folder: RunFolder,
    scenario: &Scenario,
    solution: &Solution,
) -> Result<PathBuf, Error> {
    let Solution {
        summary,
        fields,
        turning_fields,
        cycles,
        fatigue,
        failure,
        failure_state,
        last,
        plots,
        ..
    } = solution;
    let limit = scenario.model.friction * scenario.reference_load;
    let scales = PlotScales::of_run(scenario, summary);
    let mut sections = Vec::new();
    folder.write(
        "summary.json",
        &serde_json::to_vec_pretty(summary).expect("summary serialises"),
    )?;
    // `steps.csv` is written as the steps are taken (`Digest`).
    if scenario.history.is_some() {
        folder.write("cycles.csv", &cycles_table(cycles).csv())?;
    }
    let electric = scenario.model.compliance.electric.is_some();
    if let Some(profile) = fatigue {
        folder.write("fatigue.csv", &fatigue_table(profile, electric).csv())?;
    }
    {
        let mut put = |name: String, bytes: &[u8]| folder.write(&name, bytes);
        for set in fields.iter().chain(turning_fields) {
            put(
                format!("fields/{}.csv", set.stem),
                &fields_table(&set.points).csv(),
            )?;
            if let Some(map) = &set.subsurface {
                put(
                    format!("subsurface/{}.csv", set.stem),
                    &subsurface_table(map).csv(),
                )?;
            }
        }
        let mut section = |title: &str, plots: Vec<(String, String)>| -> Result<(), Error> {
            let mut names = Vec::new();
            use rayon::prelude::*;
            // PNG rendering is the slow part: the plots of a section in parallel.
            let files = plots
                .par_iter()
                .map(|(name, svg)| plot_files(name, svg, scenario.raw.output.png))
                .collect::<Result<Vec<_>, Error>>()?;
            for ((name, _), files) in plots.into_iter().zip(files) {
                for (path, bytes) in files {
                    put(path, &bytes)?;
                }
                names.push(name);
            }
            if !names.is_empty() {
                sections.push((title.to_string(), names));
            }
            Ok(())
        };
        // A history from the unloaded punch has no normal loading to draw.
        if scenario.normal_load > 0.0 {
            section(
                "End of normal loading",
                normal_loading_plots(&fields[0].points, &fields[0].ends, &scales),
            )?;
        }
        section(
            "Load history",
            plots
                .as_ref()
                .map(|p| history_plots(p, limit, failure.is_some()))
                .unwrap_or_default(),
        )?;
        let instants: Vec<FamilyMember> = fields[1..]
            .iter()
            .map(|f| (f.label.as_str(), f.points.as_slice(), f.ends))
            .collect();
        section(
            "Fretting-fatigue indicators (last complete cycle)",
            fatigue.iter().map(|p| fatigue_plot(p, &scales)).collect(),
        )?;
        section(
            "Fields at the snapshot instants",
            family_plots("snapshots", "at the snapshot instants", &instants, &scales),
        )?;
        let below: Vec<(String, String)> = fields
            .iter()
            .chain(turning_fields)
            .filter_map(|set| {
                let map = set.subsurface.as_ref()?;
                Some(subsurface_plots(&set.stem, &set.label, map, &set.ends, &scales))
            })
            .flatten()
            .collect();
        section("Fields below the surface", below)?;
    }
    if let Some(e) = failure {
        let json = failure_json(e, last.as_ref(), failure_state.as_ref());
        folder.write("failure.json", &json)?;
    }
    let mut written = folder.files().to_vec();
    written.sort();
    folder.write(
        "index.html",
        index_html(&scenario.name, &sections, &written).as_bytes(),
    )?;
    folder.commit()
}

/// The contact `(centre, half-width)` that places a run's grids (the fatigue indicators' field
/// points, the samples of a state without contact, the fields below the surface): that of the
/// end of normal loading `loaded`, or, for a history from the unloaded punch, the frictionless
/// contact at its largest P about x = 0 ([`Scenario::reference_load`]).
fn reference_contact(scenario: &Scenario, loaded: &SolvedState) -> (f64, f64) {
    match loaded.contact() {
        (_, 0.0) => (0.0, scenario.frictionless_half_width()),
        contact => contact,
    }
}


/// `failure.json`: the error, the last accepted step and the state after it (none when normal
/// loading failed; the state as a checkpoint holds it, [`crate::history::HistoryState`]).
pub(crate) fn failure_json(
    error: &Error,
    last: Option<&crate::history::StepRecord>,
    state: Option<&crate::history::HistoryState>,
) -> Vec<u8> {
    #[derive(serde::Serialize)]
    struct Failure<'a> {
        error: String,
        last_accepted_step: Option<&'a StepRecord>,
        #[serde(skip_serializing_if = "Option::is_none")]
        state: Option<&'a crate::history::HistoryState>,
    }
    let body = Failure {
        error: error.to_string(),
        last_accepted_step: last,
        state,
    };
    serde_json::to_vec_pretty(&body).expect("serialises")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::history::NoObserver;
    use crate::io::history_plots::DRAWN_STEPS;

    /// The default scenario with its cycle repeated `repeats` times (40 steps a cycle).
    fn repeated_default(repeats: usize) -> Scenario {
        let text = crate::scenario::DEFAULT_SCENARIO.replace(
            r#""repeats": 3"#,
            &format!(r#""repeats": {repeats}"#),
        );
        let raw = crate::scenario::parse(&text, Path::new("<test>")).unwrap();
        crate::scenario::validate(raw).unwrap()
    }

    /// A written run keeps none of its records in its solution and holds at most the plots'
    /// steps and a phase's: the same number over 120 and 180 cycles (4,810 and 7,210 steps,
    /// both beyond the 2·`DRAWN_STEPS` the plots draw). Its `steps.csv`, `cycles.csv` and
    /// `summary.json` are those made from every record in memory ([`solve`], with the batch
    /// cycle analysis), and its plots say which steps they draw.
    #[test]
    fn a_written_run_holds_a_bounded_number_of_records() {
        let mut held = Vec::new();
        for repeats in [120, 180] {
            let scenario = repeated_default(repeats);
            let dir = tempfile::tempdir().unwrap();
            let out = dir.path().join("run");
            let result = run(&scenario, &out).unwrap();
            let solution = &result.solution;
            assert!(solution.records.is_empty());
            assert!(
                solution.records_held <= 2 * DRAWN_STEPS + 40,
                "{} records held",
                solution.records_held
            );
            held.push(solution.records_held);
            if repeats > 120 {
                continue;
            }
            let memory = solve(&scenario, &mut NoObserver).unwrap();
            let steps = memory.records.len();
            assert_eq!(steps, 40 * repeats + 10 + 1);
            let friction = scenario.model.friction;
            let read = |name: &str| std::fs::read(out.join(name)).unwrap();
            assert!(read("steps.csv") == crate::io::csv::steps_table(&memory.records, friction).csv());
            let tolerance = scenario.raw.numerics.cycle_tolerance;
            let control = scenario.history.as_ref().unwrap().control;
            let (mut cycles, verdict) =
                crate::analysis::analyse_cycles(&memory.records, control, tolerance);
            // The largest local slip amplitudes need the states: those of the run in memory.
            assert_eq!(cycles.len(), memory.cycles.len());
            for (row, kept) in cycles.iter_mut().zip(&memory.cycles) {
                row.max_local_slip = kept.max_local_slip;
            }
            assert!(memory.cycles.iter().all(|c| c.max_local_slip.is_some()));
            assert!(read("cycles.csv") == cycles_table(&cycles).csv());
            let summary = serde_json::to_vec_pretty(&memory.summary).unwrap();
            assert!(read("summary.json") == summary);
            let history = memory.summary.history.as_ref().unwrap();
            assert_eq!(
                serde_json::to_string(&history.verdict).unwrap(),
                serde_json::to_string(&verdict).unwrap()
            );
            let svg = String::from_utf8(read("plots/hysteresis.svg")).unwrap();
            assert!(svg.contains(&format!(" of {} drawn", steps - 1)), "title");
            assert!(svg.contains(">steps 0–"), "legend");
        }
        assert_eq!(held[0], held[1], "records held over 120 and 180 cycles");
    }
}
