//! Orchestration: scenario → model → normal loading → outputs. No physics here.

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::contact::normal::{NormalLoading, NormalOptions, solve_normal};
use crate::contact::pressure::Discretisation;
use crate::contact::tangential::SlipOptions;
use crate::contact::{ContactModel, SurfacePoint};
use crate::error::Error;
use crate::halfplane::{PaperCoefficients, SurfaceCompliance, SurfaceFieldCoefficients};
use crate::output::{Protected, RunFolder, SweepFolder, csv_bytes};
use crate::scenario::{RawScenario, Scenario};

/// Constants derived from the material, reported in `summary.json`.
#[derive(Debug, Serialize)]
pub struct Derived {
    /// Surface compliance coefficients (fretsim's convention).
    pub compliance: SurfaceCompliance,
    /// The same in the paper's convention (Appendix A.2).
    pub paper_coefficients: PaperCoefficients,
    /// Δ1…Δ4 (Section 5).
    pub field_coefficients: SurfaceFieldCoefficients,
    /// Effective plane-strain compliance of the pressure problem Y* (1/Pa).
    pub pressure_compliance: f64,
    /// Shear-to-pressure coupling κ/Y* (Dundurs' β for an elastic solid).
    pub coupling_ratio: f64,
    /// Charge carried by the pressure under a conducting punch, Γ1 = kP (C/m).
    pub pressure_charge: f64,
}

/// Normal-loading results, reported in `summary.json`.
#[derive(Debug, Serialize)]
pub struct NormalSummary {
    /// Contact half-width a (m).
    pub half_width: f64,
    /// Eccentricity e = −c (m).
    pub eccentricity: f64,
    /// Stick-zone half-width b (m).
    pub stick_half_width: f64,
    /// b/a.
    pub stick_ratio: f64,
    /// Slope C of the locked-in strain (1/m).
    pub strain_slope: f64,
    /// Peak pressure (Pa).
    pub peak_pressure: f64,
    /// Resultant charge Γ (C/m).
    pub charge: f64,
    /// Contact potential φ0 relative to the datum (V), conducting punch only.
    pub potential: Option<f64>,
    /// ∫p dx (N/m), equals P.
    pub pressure_resultant: f64,
    /// ∫g dx (C/m), equals Γ.
    pub charge_resultant: f64,
    /// Block iterations.
    pub iterations: usize,
    /// Worst admissibility violations.
    pub admissibility: crate::contact::normal::Admissibility,
    /// The true gap just outside the contact ends.
    pub outside_gap: crate::contact::GapReport,
    /// Charge carried by the pressure, Γ1 = kP (C/m).
    pub pressure_charge: f64,
    /// q/(ηp) in the right slip zone: +1 when the friction points outward, −1 inward (which
    /// happens below Γ1 for a conducting punch); 0 without slip zones.
    pub right_slip_sign: f64,
}

/// `summary.json`.
#[derive(Debug, Serialize)]
pub struct Summary {
    /// fretsim version.
    pub fretsim_version: &'static str,
    /// The scenario as read.
    pub scenario: RawScenario,
    /// Derived constants.
    pub derived: Derived,
    /// The inputs as the solver used them.
    pub resolved: Resolved,
    /// Normal-loading results.
    pub normal_loading: NormalSummary,
    /// Tangential history results (absent without a history).
    pub history: Option<HistorySummary>,
    /// The field snapshots written at the requested times.
    pub snapshots: Vec<SnapshotSummary>,
    /// Work counters and checks.
    pub solver: SolverStatistics,
    /// Warnings.
    pub warnings: Vec<String>,
}

/// What a run produced.
#[derive(Debug)]
pub struct RunResult {
    /// Output folder.
    pub out_dir: PathBuf,
    /// Summary (as written).
    pub summary: Summary,
    /// The sampled fields: the end of normal loading, then one set per snapshot time.
    pub fields: Vec<FieldSet>,
}

/// Everything a run computes, before anything is written: what [`solve`] returns and what
/// the output files are made of.
#[derive(Debug)]
pub struct Solution {
    /// The summary (`summary.json`).
    pub summary: Summary,
    /// The sampled fields: the end of normal loading, then one set per snapshot time reached.
    pub fields: Vec<FieldSet>,
    /// The fields at the turning points and the last step (empty when
    /// `output.turning_point_fields` is off).
    pub turning_fields: Vec<FieldSet>,
    /// One record per accepted step (step 0 is the end of normal loading).
    pub records: Vec<crate::history::StepRecord>,
    /// The cycles of the history.
    pub cycles: Vec<CycleRow>,
    /// The solver failure that stopped the history part-way, if any.
    pub failure: Option<Error>,
}

/// Derived constants of a model at normal load P.
pub fn derived(model: &ContactModel, normal_load: f64) -> Derived {
    let split = model.charge_split(normal_load);
    let ystar = model.pressure_compliance(split);
    Derived {
        compliance: model.compliance,
        paper_coefficients: model.compliance.paper_coefficients(),
        field_coefficients: model.field_coefficients,
        pressure_compliance: ystar,
        coupling_ratio: model.pressure_shear_coupling(split) / ystar,
        pressure_charge: model.pressure_charge(normal_load),
    }
}

/// Sample points for field output: the contact and a margin of one half-width each side,
/// never exactly at the contact ends (where g and Dx0 are singular for a conducting punch).
pub fn field_points(centre: f64, half_width: f64, count: usize) -> Vec<f64> {
    (0..count)
        .map(|i| centre + 2.0 * half_width * ((2 * i + 1) as f64 - count as f64) / count as f64)
        .collect()
}

fn normal_summary(model: &ContactModel, n: &NormalLoading) -> NormalSummary {
    let s = &n.state;
    let w_total = s.potential_charge_force();
    NormalSummary {
        half_width: s.half_width,
        eccentricity: -s.centre,
        stick_half_width: n.stick_half_width,
        stick_ratio: n.stick_half_width / s.half_width,
        strain_slope: n.strain_slope,
        peak_pressure: s.pressure_at(s.centre),
        charge: s.charge,
        potential: s.potential,
        pressure_resultant: s.pressure_force(),
        // The inverse-square-root part integrates exactly from its series; the rest by quadrature.
        charge_resultant: s.split.ratio * s.pressure_force() + w_total,
        iterations: n.iterations,
        admissibility: n.admissibility,
        outside_gap: model.outside_gap(s),
        pressure_charge: model.pressure_charge(s.normal_load),
        right_slip_sign: s.traction.right_sign,
    }
}

/// Solve a validated scenario and write its outputs into `out_dir`, which must be new or a
/// previous fretsim output ([`RunFolder::claim`]).
pub fn run(scenario: &Scenario, out_dir: &Path) -> Result<RunResult, Error> {
    let folder = RunFolder::claim(out_dir, &Protected::new(None))?;
    run_with(scenario, folder, &mut crate::history::NoObserver)
}

/// Summary of the tangential history, in `summary.json`.
#[derive(Debug, Serialize)]
pub struct HistorySummary {
    /// Number of accepted steps after normal loading.
    pub steps: usize,
    /// Number of phases (monotonic segments between reversals).
    pub phases: usize,
    /// The states at the end of each phase: step, Q, stick ends, eccentricity.
    pub turning_points: Vec<crate::history::StepRecord>,
    /// The failure, if the run stopped early.
    pub failure: Option<String>,
    /// Per-cycle table.
    pub cycles: Vec<CycleRow>,
    /// Shakedown verdict.
    pub verdict: Verdict,
    /// Tolerance of the verdict (relative).
    pub verdict_tolerance: f64,
}

/// Inputs as the solver used them: a preset resolved to its constants, and the load history
/// in N/m with the cycle block expanded and the snapshot points added.
#[derive(Debug, Serialize)]
pub struct Resolved {
    /// Material constants.
    pub material: crate::material::Material,
    /// The load history (absent without one).
    pub load_history: Option<crate::history::LoadHistory>,
}

/// Work counters and checks of the whole run, in `summary.json`.
#[derive(Debug, Serialize)]
pub struct SolverStatistics {
    /// Collocation nodes M per interval.
    pub collocation_points: usize,
    /// Block iterations of the normal-loading solve.
    pub normal_loading_iterations: usize,
    /// Accepted load steps after normal loading.
    pub history_steps: usize,
    /// Newton iterations summed over the history (`newton_iterations` in `steps.csv`).
    pub newton_iterations: usize,
    /// Most Newton iterations in one step.
    pub max_newton_iterations: usize,
    /// Residual evaluations summed over the history (`evaluations` in `steps.csv`).
    pub residual_evaluations: usize,
    /// Largest final residual of a step.
    pub max_residual: Option<f64>,
    /// Worst `stick_excess` of a step (≤ 0 when admissible).
    pub worst_stick_excess: Option<f64>,
    /// Worst `slip_reversal` of a step (≤ 0 when admissible).
    pub worst_slip_reversal: Option<f64>,
}

/// A field snapshot at a requested time, in `summary.json`.
#[derive(Debug, Clone, Serialize)]
pub struct SnapshotSummary {
    /// Requested time (s), from `output.snapshots`.
    pub t: f64,
    /// The field file, relative to the output folder.
    pub file: String,
    /// The step solved at that time.
    pub step: usize,
    /// Time of that step (s); equals `t` within the scenario's time tolerance.
    pub step_t: f64,
    /// Tangential load Q (N/m).
    pub q: f64,
    /// Q/(ηP).
    pub q_over_limit: f64,
    /// Regime of the step.
    pub regime: crate::history::Regime,
    /// Phase of the step.
    pub phase: usize,
    /// Contact half-width a (m).
    pub half_width: f64,
    /// Eccentricity e = −c (m).
    pub eccentricity: f64,
    /// Stick-zone left end (m).
    pub stick_lo: f64,
    /// Stick-zone right end (m).
    pub stick_hi: f64,
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
}

/// Keeps, while the history runs, the states that the field files need: the turning points
/// (the last step of each phase), the last step, and the steps at the snapshot times.
struct Snapshots<'a> {
    inner: &'a mut dyn crate::history::Observer,
    previous: Option<(crate::history::StepRecord, crate::contact::ContactState)>,
    kept: Vec<(crate::history::StepRecord, crate::contact::ContactState)>,
    times: &'a [f64],
    tolerance: f64,
    at_times: Vec<Option<(crate::history::StepRecord, crate::contact::ContactState)>>,
}

impl crate::history::Observer for Snapshots<'_> {
    fn on_step(
        &mut self,
        record: &crate::history::StepRecord,
        state: &crate::contact::ContactState,
    ) {
        if let Some((prev, prev_state)) = self.previous.take()
            && prev.phase != record.phase
            && prev.phase > 0
        {
            self.kept.push((prev, prev_state));
        }
        self.previous = Some((record.clone(), state.clone()));
        // The last step at a snapshot time wins (a ramp to a non-zero first point is solved
        // in several steps at the same time).
        for (t, slot) in self.times.iter().zip(self.at_times.iter_mut()) {
            if (record.t - t).abs() <= self.tolerance {
                *slot = Some((record.clone(), state.clone()));
            }
        }
        self.inner.on_step(record, state);
    }

    fn on_phase(&mut self, phase: usize, memory: &crate::contact::memory::Memory) {
        self.inner.on_phase(phase, memory);
    }
}

fn solver_statistics(
    scenario: &Scenario,
    normal: &NormalLoading,
    records: &[crate::history::StepRecord],
) -> SolverStatistics {
    let steps = records.iter().skip(1);
    let max = |f: &dyn Fn(&crate::history::StepRecord) -> f64| {
        records
            .iter()
            .skip(1)
            .map(f)
            .filter(|x| x.is_finite())
            .reduce(f64::max)
    };
    SolverStatistics {
        collocation_points: scenario.collocation_points,
        normal_loading_iterations: normal.iterations,
        history_steps: records.len().saturating_sub(1),
        newton_iterations: steps.clone().map(|r| r.iterations).sum(),
        max_newton_iterations: steps.clone().map(|r| r.iterations).max().unwrap_or(0),
        residual_evaluations: steps.map(|r| r.newton_iterations).sum(),
        max_residual: max(&|r| r.residual),
        worst_stick_excess: max(&|r| r.admissibility.stick_excess),
        worst_slip_reversal: max(&|r| r.admissibility.slip_reversal),
    }
}

/// As [`run`], reporting each accepted step to `observer` (progress bars).
pub fn run_with(
    scenario: &Scenario,
    folder: RunFolder,
    observer: &mut dyn crate::history::Observer,
) -> Result<RunResult, Error> {
    match run_partial(scenario, folder, observer)? {
        (result, None) => Ok(result),
        (_, Some(failure)) => Err(failure),
    }
}

/// As [`run_with`], but a solver failure during the history is returned beside what was
/// written (the summary and the fields reached) instead of replacing it. A failure of the
/// normal loading is returned as `Err` after `failure.json` is written; so is a write error.
pub fn run_partial(
    scenario: &Scenario,
    mut folder: RunFolder,
    observer: &mut dyn crate::history::Observer,
) -> Result<(RunResult, Option<Error>), Error> {
    crate::output::pause_point("solve");
    match solve(scenario, observer) {
        Ok(mut solution) => {
            let out_dir = write_solution(folder, scenario, &solution)?;
            let failure = solution.failure.take();
            Ok((
                RunResult {
                    out_dir,
                    summary: solution.summary,
                    fields: solution.fields,
                },
                failure,
            ))
        }
        Err(error) => {
            folder.write("failure.json", &failure_json(&error, None))?;
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
    let model = &scenario.model;
    let disc = Discretisation::new(scenario.collocation_points);
    let normal = solve_normal(model, &disc, scenario.normal_load, NormalOptions::default())
        .map_err(|failure| Error::Solve {
            context: "normal loading".into(),
            failure,
        })?;
    let mut warnings = Vec::new();
    let gamma1 = model.pressure_charge(scenario.normal_load);
    let gap = model.outside_gap(&normal.state);
    if gap.min_gap < 0.0 {
        warnings.push(format!(
            "the surface interpenetrates the punch just outside the contact: gap {:.3e} m at x = {:.4e} m \
             (a²/2R = {:.3e} m); Γ = {:.4e} C/m exceeds the charge carried by the pressure Γ1 = kP = {gamma1:.4e} C/m, \
             and the conducting-punch model (smooth pressure at the contact ends) then admits no state with a non-negative gap",
            gap.min_gap, gap.at, gap.scale, normal.state.charge
        ));
    }
    // The tangential history, if any; a failure keeps the steps already solved.
    let mut records = Vec::new();
    let mut failure = None;
    let mut snapshots = Snapshots {
        inner: observer,
        previous: None,
        kept: Vec::new(),
        times: &scenario.snapshots,
        tolerance: scenario.time_tolerance,
        at_times: vec![None; scenario.snapshots.len()],
    };
    if let Some(history) = &scenario.history {
        match crate::history::run_history(
            model,
            &disc,
            &normal,
            history,
            SlipOptions::default(),
            &mut snapshots,
        ) {
            Ok(run) => records = run.records,
            Err(f) => {
                let f = *f;
                records = f.records;
                failure = Some(Error::Solve {
                    context: f.failure.to_string(),
                    failure: f.failure.failure,
                });
            }
        }
    }
    let solver_tolerance = SlipOptions::default().tolerance;
    let stalled: Vec<&crate::history::StepRecord> = records
        .iter()
        .filter(|r| r.residual >= solver_tolerance)
        .collect();
    if let Some(worst) = stalled
        .iter()
        .max_by(|x, y| x.residual.total_cmp(&y.residual))
    {
        warnings.push(format!(
            "{} step(s) accepted with a stalled residual above the solver tolerance {solver_tolerance:e} \
             (largest {:.3e} at step {}, t = {} s): the iteration stopped improving below the \
             stall tolerance; see the residual column of steps.csv",
            stalled.len(),
            worst.residual,
            worst.step,
            worst.t
        ));
    }
    let limit = model.friction * scenario.normal_load;
    let tolerance = scenario.raw.numerics.cycle_tolerance;
    let (cycles, verdict) = analyse_cycles(&records, tolerance);
    let history_summary = scenario.history.as_ref().map(|_| {
        let turning_points = records
            .windows(2)
            .filter(|w| w[0].phase != w[1].phase && w[0].phase > 0)
            .map(|w| w[0].clone())
            .chain(records.last().filter(|r| r.phase > 0).cloned())
            .collect();
        HistorySummary {
            steps: records.len().saturating_sub(1),
            phases: records.last().map_or(0, |r| r.phase),
            turning_points,
            failure: failure.as_ref().map(|e| e.to_string()),
            cycles: cycles.clone(),
            verdict,
            verdict_tolerance: tolerance,
        }
    });
    // Sampled fields: the end of normal loading, then each snapshot time reached.
    let n = scenario.raw.output.field_points;
    let sample = |state: &crate::contact::ContactState| -> Vec<SurfacePoint> {
        field_points(state.centre, state.half_width, n)
            .into_iter()
            .map(|x| model.surface_point(state, x))
            .collect()
    };
    let mut fields = vec![FieldSet {
        stem: "normal_loading".into(),
        label: "end of normal loading".into(),
        points: sample(&normal.state),
    }];
    let mut snapshot_rows = Vec::new();
    for (&t, kept) in scenario.snapshots.iter().zip(&snapshots.at_times) {
        let stem = crate::scenario::snapshot_stem(t);
        match kept {
            Some((rec, state)) => {
                fields.push(FieldSet {
                    label: format!("t = {t} s, Q/(ηP) = {:.3}", rec.q / limit),
                    stem: stem.clone(),
                    points: sample(state),
                });
                snapshot_rows.push(SnapshotSummary {
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
            None => warnings.push(format!(
                "snapshot t = {t} s was not reached (the history stopped at t = {} s); fields/{stem}.csv is not written",
                records.last().map_or(f64::NAN, |r| r.t)
            )),
        }
    }
    let summary = Summary {
        fretsim_version: env!("CARGO_PKG_VERSION"),
        scenario: scenario.raw.clone(),
        resolved: Resolved {
            material: model.material,
            load_history: scenario.history.clone(),
        },
        derived: derived(model, scenario.normal_load),
        normal_loading: normal_summary(model, &normal),
        history: history_summary,
        snapshots: snapshot_rows,
        solver: solver_statistics(scenario, &normal, &records),
        warnings,
    };
    // Turning points and the last step, unless switched off.
    let mut turning_fields = Vec::new();
    if scenario.raw.output.turning_point_fields {
        for (rec, state) in snapshots.kept.iter().chain(snapshots.previous.iter()) {
            turning_fields.push(FieldSet {
                stem: format!("step_{:05}", rec.step),
                label: format!("step {}", rec.step),
                points: sample(state),
            });
        }
    }
    Ok(Solution {
        summary,
        fields,
        turning_fields,
        records,
        cycles,
        failure,
    })
}

/// Write a solution's files into its claimed folder and swap the folder into place.
fn write_solution(
    mut folder: RunFolder,
    scenario: &Scenario,
    solution: &Solution,
) -> Result<PathBuf, Error> {
    let Solution {
        summary,
        fields,
        turning_fields,
        records,
        cycles,
        failure,
    } = solution;
    let limit = scenario.model.friction * scenario.normal_load;
    let mut sections = Vec::new();
    {
        let mut put = |name: String, bytes: &[u8]| folder.write(&name, bytes);
        put(
            "summary.json".into(),
            &serde_json::to_vec_pretty(summary).expect("summary serialises"),
        )?;
        if scenario.history.is_some() {
            put("steps.csv".into(), &steps_csv(records, limit))?;
            put("cycles.csv".into(), &cycles_csv(cycles))?;
        }
        for set in fields.iter().chain(turning_fields) {
            put(format!("fields/{}.csv", set.stem), &fields_csv(&set.points))?;
        }
        let mut section = |title: &str, plots: Vec<(String, String)>| -> Result<(), Error> {
            let mut names = Vec::new();
            for (name, svg) in plots {
                put(format!("plots/{name}.svg"), svg.as_bytes())?;
                names.push(name);
            }
            if !names.is_empty() {
                sections.push((title.to_string(), names));
            }
            Ok(())
        };
        section(
            "End of normal loading",
            normal_loading_plots(&fields[0].points),
        )?;
        section(
            "Load history",
            history_plots(records, limit, failure.is_some()),
        )?;
        let instants: Vec<(&str, &[SurfacePoint])> = fields[1..]
            .iter()
            .map(|f| (f.label.as_str(), f.points.as_slice()))
            .collect();
        section(
            "Fields at the snapshot instants",
            family_plots("snapshots", "at the snapshot instants", &instants),
        )?;
    }
    if let Some(e) = failure {
        folder.write("failure.json", &failure_json(e, records.last()))?;
    }
    let mut written = folder.files().to_vec();
    written.sort();
    folder.write(
        "index.html",
        index_html(&scenario.name, &sections, &written).as_bytes(),
    )?;
    folder.commit()
}

/// `failure.json`: the error and the last accepted step (none when normal loading failed).
fn failure_json(error: &Error, last: Option<&crate::history::StepRecord>) -> Vec<u8> {
    let body = serde_json::json!({
        "error": error.to_string(),
        "last_accepted_step": last,
    });
    serde_json::to_vec_pretty(&body).expect("serialises")
}

/// The plots of the fields at the end of normal loading.
fn normal_loading_plots(points: &[SurfacePoint]) -> Vec<(String, String)> {
    use crate::plot::{Series, line_plot};
    let field =
        |f: &dyn Fn(&SurfacePoint) -> f64| points.iter().map(|p| (p.x, f(p))).collect::<Vec<_>>();
    let one = |name: &str, title: &str, y: &str, label: &str, f: &dyn Fn(&SurfacePoint) -> f64| {
        (
            name.to_string(),
            line_plot(
                &format!("End of normal loading: {title}"),
                "x (m)",
                y,
                &[Series {
                    label,
                    points: field(f),
                    colour: "black",
                }],
            ),
        )
    };
    vec![
        (
            "normal_loading_tractions".into(),
            line_plot(
                "End of normal loading: pressure p and shear traction q",
                "x (m)",
                "p, q (Pa)",
                &[
                    Series {
                        label: "p",
                        points: field(&|p| p.pressure),
                        colour: "black",
                    },
                    Series {
                        label: "q (on the half-plane)",
                        points: field(&|p| p.traction),
                        colour: "crimson",
                    },
                ],
            ),
        ),
        one(
            "normal_loading_charge",
            "surface charge g",
            "g (C/m²)",
            "g",
            &|p| p.charge,
        ),
        one(
            "normal_loading_sigma_xx",
            "surface stress σxx0",
            "σxx0 (Pa)",
            "σxx0",
            &|p| p.sigma_xx,
        ),
        one(
            "normal_loading_d_x",
            "in-plane electric displacement Dx0",
            "Dx0 (C/m²)",
            "Dx0",
            &|p| p.d_x,
        ),
    ]
}

/// One plot per field quantity (p, q, g, σxx0, Dx0) with one curve per member of a family
/// (snapshot instants of a run, or variants of a sweep), named `<prefix>_<quantity>`. Empty
/// when the family is empty.
pub fn family_plots(
    prefix: &str,
    what: &str,
    family: &[(&str, &[SurfacePoint])],
) -> Vec<(String, String)> {
    use crate::plot::{PALETTE, Series, line_plot};
    if family.is_empty() {
        return Vec::new();
    }
    type Quantity = (
        &'static str,
        &'static str,
        &'static str,
        fn(&SurfacePoint) -> f64,
    );
    let quantities: [Quantity; 5] = [
        ("p", "Pressure p", "p (Pa)", |p| p.pressure),
        ("q", "Shear traction q (on the half-plane)", "q (Pa)", |p| {
            p.traction
        }),
        ("g", "Surface charge g", "g (C/m²)", |p| p.charge),
        ("sigma_xx", "Surface stress σxx0", "σxx0 (Pa)", |p| {
            p.sigma_xx
        }),
        (
            "d_x",
            "In-plane electric displacement Dx0",
            "Dx0 (C/m²)",
            |p| p.d_x,
        ),
    ];
    quantities
        .iter()
        .map(|(key, title, y, f)| {
            let series: Vec<Series> = family
                .iter()
                .enumerate()
                .map(|(k, (label, points))| Series {
                    label,
                    points: points.iter().map(|p| (p.x, f(p))).collect(),
                    colour: PALETTE[k % PALETTE.len()],
                })
                .collect();
            (
                format!("{prefix}_{key}"),
                line_plot(&format!("{title} {what}"), "x (m)", y, &series),
            )
        })
        .collect()
}

/// With a history (and at least one step after normal loading): the hysteresis loop and the
/// stick-zone ends.
fn history_plots(
    records: &[crate::history::StepRecord],
    limit: f64,
    failed: bool,
) -> Vec<(String, String)> {
    use crate::plot::{Series, line_plot};
    if records.len() <= 1 {
        return Vec::new();
    }
    let note = if failed { " (stopped early)" } else { "" };
    let loop_pts: Vec<(f64, f64)> = records
        .iter()
        .map(|r| (r.displacement, r.q / limit))
        .collect();
    let ends = |f: &dyn Fn(&crate::history::StepRecord) -> f64| {
        records
            .iter()
            .map(|r| (r.t, f(r) / r.half_width))
            .collect::<Vec<_>>()
    };
    vec![
        (
            "hysteresis".into(),
            line_plot(
                &format!("Fretting loop{note}"),
                "tangential displacement δ (m)",
                "Q/(ηP) (–)",
                &[Series {
                    label: "Q–δ",
                    points: loop_pts,
                    colour: "black",
                }],
            ),
        ),
        (
            "stick_zone".into(),
            line_plot(
                &format!("Stick-zone ends and contact ends{note}"),
                "time t (s)",
                "x / a (–)",
                &[
                    Series {
                        label: "stick-zone left end",
                        points: ends(&|r| r.stick_lo),
                        colour: "navy",
                    },
                    Series {
                        label: "stick-zone right end",
                        points: ends(&|r| r.stick_hi),
                        colour: "crimson",
                    },
                    Series {
                        label: "contact ends",
                        points: ends(&|r| -r.eccentricity - r.half_width),
                        colour: "gray",
                    },
                    Series {
                        label: "",
                        points: ends(&|r| -r.eccentricity + r.half_width),
                        colour: "gray",
                    },
                ],
            ),
        ),
    ]
}

/// `index.html`: every plot on one page, in sections, and links to every file.
pub fn index_html(name: &str, sections: &[(String, Vec<String>)], files: &[String]) -> String {
    use crate::plot::escape;
    let name = escape(name);
    let mut body = String::new();
    for (title, plots) in sections {
        body.push_str(&format!("<h2>{}</h2>\n", escape(title)));
        for p in plots {
            body.push_str(&format!(
                "<figure><img src=\"plots/{p}.svg\" alt=\"{p}\"><figcaption>plots/{p}.svg</figcaption></figure>\n"
            ));
        }
    }
    let links: String = files
        .iter()
        .map(|f| format!("<li><a href=\"{f}\">{f}</a></li>\n", f = escape(f)))
        .collect();
    format!(
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>fretsim: {name}</title></head>\n<body>\n<h1>fretsim: {name}</h1>\n<p>Columns and units of every file: see the fretsim README.</p>\n{body}<h2>Files</h2>\n<ul>\n{links}</ul>\n</body></html>\n"
    )
}

/// A fields CSV: `x_m, p_Pa, q_Pa, g_C_per_m2, sigma_xx_Pa, d_x_C_per_m2`.
fn fields_csv(points: &[SurfacePoint]) -> Vec<u8> {
    let rows: Vec<Vec<f64>> = points
        .iter()
        .map(|p| vec![p.x, p.pressure, p.traction, p.charge, p.sigma_xx, p.d_x])
        .collect();
    csv_bytes(
        &[
            "x_m",
            "p_Pa",
            "q_Pa",
            "g_C_per_m2",
            "sigma_xx_Pa",
            "d_x_C_per_m2",
        ],
        &rows,
    )
}

/// `cycles.csv`: one row per fretting cycle.
fn cycles_csv(cycles: &[CycleRow]) -> Vec<u8> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record([
        "cycle",
        "first_step",
        "last_step",
        "Q_start_N_per_m",
        "Q_min_N_per_m",
        "Q_end_N_per_m",
        "loop_area_J_per_m",
        "friction_work_J_per_m",
        "normal_work_J_per_m",
        "electric_work_J_per_m",
        "delta_at_max_m",
        "delta_at_min_m",
        "stick_lo_at_max_m",
        "stick_hi_at_max_m",
        "stick_lo_at_min_m",
        "stick_hi_at_min_m",
        "change_vs_previous",
        "compared_with_cycle",
    ])
    .expect("in-memory write");
    let f = |x: f64| format!("{x:.10e}");
    for c in cycles {
        w.write_record([
            c.cycle.to_string(),
            c.steps.0.to_string(),
            c.steps.1.to_string(),
            f(c.loads.0),
            f(c.loads.1),
            f(c.loads.2),
            f(c.loop_area),
            f(c.friction_work),
            f(c.normal_work),
            f(c.electric_work),
            f(c.displacement_extremes.0),
            f(c.displacement_extremes.1),
            f(c.stick_at_max.0),
            f(c.stick_at_max.1),
            f(c.stick_at_min.0),
            f(c.stick_at_min.1),
            c.change.map(f).unwrap_or_default(),
            c.compared_with.map(|k| k.to_string()).unwrap_or_default(),
        ])
        .expect("in-memory write");
    }
    w.into_inner().expect("in-memory write")
}

/// `steps.csv`: one row per accepted step.
fn steps_csv(records: &[crate::history::StepRecord], limit: f64) -> Vec<u8> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record([
        "step",
        "t_s",
        "Q_N_per_m",
        "Q_over_etaP",
        "regime",
        "phase",
        "a_m",
        "e_m",
        "stick_lo_m",
        "stick_hi_m",
        "left_slip_sign",
        "right_slip_sign",
        "newton_iterations",
        "evaluations",
        "residual",
        "stick_excess",
        "slip_reversal",
        "delta_m",
        "dissipation_J_per_m",
    ])
    .expect("in-memory write");
    for r in records {
        let regime = serde_json::to_value(r.regime)
            .ok()
            .and_then(|v| v.as_str().map(String::from))
            .unwrap_or_default();
        let f = |x: f64| format!("{x:.10e}");
        w.write_record([
            r.step.to_string(),
            f(r.t),
            f(r.q),
            f(r.q / limit),
            regime,
            r.phase.to_string(),
            f(r.half_width),
            f(r.eccentricity),
            f(r.stick_lo),
            f(r.stick_hi),
            f(r.left_slip_sign),
            f(r.right_slip_sign),
            r.iterations.to_string(),
            r.newton_iterations.to_string(),
            f(r.residual),
            f(r.admissibility.stick_excess),
            f(r.admissibility.slip_reversal),
            f(r.displacement),
            f(r.dissipation),
        ])
        .expect("in-memory write");
    }
    w.into_inner().expect("in-memory write")
}

/// Most variants in a sweep (the product of the `--vary` counts).
pub const MAX_SWEEP_VARIANTS: usize = 100_000;

/// One varied field of a sweep: `path=start:end:count` (linear spacing, count ≥ 1).
#[derive(Debug, Clone, PartialEq)]
pub struct Vary {
    /// Dotted JSON path, e.g. `friction` or `punch.electrode.charge`.
    pub path: String,
    /// Values.
    pub values: Vec<f64>,
}

impl std::str::FromStr for Vary {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let (path, range) = s
            .split_once('=')
            .ok_or_else(|| format!("`{s}` must read FIELD=START:END:COUNT"))?;
        let parts: Vec<&str> = range.split(':').collect();
        let [start, end, count] = parts.as_slice() else {
            return Err(format!("`{range}` must read START:END:COUNT"));
        };
        let start: f64 = start
            .parse()
            .map_err(|_| format!("START `{start}` is not a number"))?;
        let end: f64 = end
            .parse()
            .map_err(|_| format!("END `{end}` is not a number"))?;
        let count: usize = count
            .parse()
            .map_err(|_| format!("COUNT `{count}` is not a whole number"))?;
        if count == 0 || !start.is_finite() || !end.is_finite() {
            return Err("COUNT must be ≥ 1 and START, END finite".into());
        }
        if count > MAX_SWEEP_VARIANTS {
            return Err(format!(
                "COUNT {count} is invalid; it must be at most {MAX_SWEEP_VARIANTS} (variants in a sweep)"
            ));
        }
        let values = (0..count)
            .map(|i| {
                if count == 1 {
                    start
                } else {
                    start + (end - start) * i as f64 / (count - 1) as f64
                }
            })
            .collect();
        Ok(Self {
            path: path.to_string(),
            values,
        })
    }
}

/// A shard of a sweep: run every N-th variant starting at I (1-based `I/N`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// I (1-based).
    pub index: usize,
    /// N.
    pub count: usize,
}

impl std::str::FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let (i, n) = s
            .split_once('/')
            .ok_or_else(|| format!("`{s}` must read I/N"))?;
        let index: usize = i
            .parse()
            .map_err(|_| format!("I `{i}` is not a whole number"))?;
        let count: usize = n
            .parse()
            .map_err(|_| format!("N `{n}` is not a whole number"))?;
        if count == 0 || index == 0 || index > count {
            return Err(format!("`{s}` needs 1 ≤ I ≤ N"));
        }
        Ok(Self { index, count })
    }
}

/// Whether the scenario field at dotted `path` is an integer: its value in the built-in
/// default scenario with every field written out (the schema; a float field written as `2000`
/// in a file stays a float).
fn is_integer_field(path: &str) -> bool {
    static SCHEMA: std::sync::OnceLock<serde_json::Value> = std::sync::OnceLock::new();
    let schema = SCHEMA.get_or_init(|| {
        serde_json::to_value(&crate::scenario::default_scenario().raw).unwrap_or_default()
    });
    path.split('.')
        .try_fold(schema, |v, k| v.get(k))
        .is_some_and(|v| v.is_u64() || v.is_i64())
}

/// `x` as the JSON value of the field at `path`: an integer for an integer field (an error
/// unless `x` is a whole number), else a float.
fn field_value(path: &str, x: f64) -> Result<serde_json::Value, String> {
    if !is_integer_field(path) {
        return Ok(serde_json::json!(x));
    }
    if !(x.is_finite() && x.fract() == 0.0) {
        return Err(format!(
            "{x} is invalid; it must be a whole number (the field is an integer)"
        ));
    }
    // Beyond 2^53 the integer is not exact; the scenario's parser then names the field.
    Ok(if x.abs() <= 2f64.powi(53) {
        serde_json::json!(x as i64)
    } else {
        serde_json::json!(x)
    })
}

fn set_path(value: &mut serde_json::Value, path: &str, x: f64) -> Result<(), String> {
    let mut cur = value;
    let keys: Vec<&str> = path.split('.').collect();
    for (i, k) in keys.iter().enumerate() {
        let obj = cur
            .as_object_mut()
            .ok_or_else(|| format!("`{path}`: `{}` is not an object", keys[..i].join(".")))?;
        if i + 1 == keys.len() {
            obj.insert((*k).to_string(), field_value(path, x)?);
            return Ok(());
        }
        cur = obj
            .entry((*k).to_string())
            .or_insert_with(|| serde_json::json!({}));
    }
    Ok(())
}

#[cfg(test)]
mod vary_tests {
    use super::*;

    #[test]
    fn a_vary_count_above_the_variant_limit_is_rejected() {
        assert_eq!(
            "friction=0:1:100001".parse::<Vary>().unwrap_err(),
            "COUNT 100001 is invalid; it must be at most 100000 (variants in a sweep)"
        );
        assert!("friction=0:1:100000".parse::<Vary>().is_ok());
    }

    #[test]
    fn a_sweep_product_above_the_variant_limit_is_rejected() {
        let vary: Vec<Vary> = ["friction=0.1:0.3:1000", "normal_load=1000:2000:101"]
            .iter()
            .map(|v| v.parse().unwrap())
            .collect();
        let text = crate::scenario::DEFAULT_SCENARIO;
        match sweep_variants(text, Path::new("t.json"), &vary, None) {
            Err(e @ Error::InvalidScenario { .. }) => assert_eq!(
                e.to_string(),
                "t.json: 1 problem(s)\n  - `--vary` = 1000 × 101 variants is invalid; it must be at most 100000"
            ),
            other => panic!("{:?}", other.map(|v| v.len())),
        }
    }

    #[test]
    fn integer_fields_receive_integers() {
        let mut v = serde_json::json!({"numerics": {"collocation_points": 64}, "friction": 0.3});
        set_path(&mut v, "numerics.collocation_points", 32.0).unwrap();
        set_path(&mut v, "tangential_history.repeats", 5.0).unwrap();
        set_path(&mut v, "friction", 1.0).unwrap();
        assert_eq!(v["numerics"]["collocation_points"], serde_json::json!(32));
        assert!(v["tangential_history"]["repeats"].is_u64());
        assert!(v["friction"].is_f64());
        assert_eq!(
            set_path(&mut v, "output.field_points", 402.5).unwrap_err(),
            "402.5 is invalid; it must be a whole number (the field is an integer)"
        );
        // A sweep over M runs (it failed to parse when M was written as a float).
        let vary = vec![
            "numerics.collocation_points=16:32:2"
                .parse::<Vary>()
                .unwrap(),
        ];
        let text = crate::scenario::DEFAULT_SCENARIO;
        let variants = sweep_variants(text, Path::new("t.json"), &vary, None).unwrap();
        let m: Vec<usize> = variants.iter().map(|v| v.2.collocation_points).collect();
        assert_eq!(m, [16, 32]);
    }
}

/// Options of a sweep.
#[derive(Debug, Clone, Copy, Default)]
pub struct SweepOptions {
    /// Run only one shard of the variants.
    pub shard: Option<Shard>,
    /// Run each variant's whole scenario (history included) into `variant_NNNN/` instead of
    /// the normal-loading solve alone.
    pub runs: bool,
}

/// What a sweep wrote.
#[derive(Debug)]
pub struct SweepOutput {
    /// The CSV file (`sweep.csv` or `sweep-I-of-N.csv`).
    pub csv: PathBuf,
    /// Variants run.
    pub variants: usize,
    /// Variants whose solve failed (their `error` column is filled).
    pub failed: usize,
    /// The `failure.json` files of the failed variants (with [`SweepOptions::runs`]).
    pub failure_files: Vec<PathBuf>,
}

impl SweepOutput {
    /// The sweep as an error when any variant failed (exit status 1).
    pub fn check(self) -> Result<Self, Error> {
        if self.failed == 0 {
            return Ok(self);
        }
        Err(Error::SweepFailed {
            failed: self.failed,
            variants: self.variants,
            csv: self.csv,
            failure_files: self.failure_files,
        })
    }
}

/// The folder of variant `index` of a sweep run with [`SweepOptions::runs`].
pub fn variant_dir(index: usize) -> String {
    format!("variant_{index:04}")
}

/// A legend label for a variant: `friction = 0.3, punch.electrode.charge = 6e-7`.
fn variant_label(vary: &[Vary], values: &[f64]) -> String {
    vary.iter()
        .zip(values)
        .map(|(v, x)| {
            // Six significant digits, without the noise of the linear spacing.
            let x: f64 = format!("{x:.5e}").parse().unwrap_or(*x);
            if x == 0.0 || (1e-3..1e4).contains(&x.abs()) {
                format!("{} = {x}", v.path)
            } else {
                format!("{} = {x:e}", v.path)
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// The scenario variants of a sweep: every point of the Cartesian product of `vary` (in the
/// shard), validated before any is solved.
fn sweep_variants(
    text: &str,
    source: &Path,
    vary: &[Vary],
    shard: Option<Shard>,
) -> Result<Vec<(usize, Vec<f64>, Scenario)>, Error> {
    let base: serde_json::Value = serde_json::from_str(text).map_err(|e| Error::ParseScenario {
        path: source.to_path_buf(),
        at: String::new(),
        line: e.line(),
        column: e.column(),
        message: e.to_string(),
    })?;
    let total = vary
        .iter()
        .try_fold(1usize, |n, v| n.checked_mul(v.values.len()))
        .filter(|&n| n <= MAX_SWEEP_VARIANTS);
    if total.is_none() {
        let counts: Vec<String> = vary.iter().map(|v| v.values.len().to_string()).collect();
        return Err(Error::InvalidScenario {
            path: source.to_path_buf(),
            issues: vec![crate::error::Issue::new(
                "--vary",
                format!(
                    "{} variants is invalid; it must be at most {MAX_SWEEP_VARIANTS}",
                    counts.join(" × ")
                ),
            )],
        });
    }
    // Cartesian product of the values.
    let mut combos: Vec<Vec<f64>> = vec![Vec::new()];
    for v in vary {
        combos = combos
            .into_iter()
            .flat_map(|c| v.values.iter().map(move |x| [c.clone(), vec![*x]].concat()))
            .collect();
    }
    let selected: Vec<(usize, Vec<f64>)> = combos
        .into_iter()
        .enumerate()
        .filter(|(i, _)| shard.is_none_or(|s| i % s.count == s.index - 1))
        .collect();
    let mut scenarios = Vec::new();
    let mut issues = Vec::new();
    for (i, values) in &selected {
        let mut v = base.clone();
        for (var, x) in vary.iter().zip(values) {
            set_path(&mut v, &var.path, *x).map_err(|m| Error::InvalidScenario {
                path: source.to_path_buf(),
                issues: vec![crate::error::Issue::new(var.path.clone(), m)],
            })?;
        }
        let raw = crate::scenario::parse(&v.to_string(), source)?;
        match crate::scenario::validate(raw) {
            Ok(s) => scenarios.push((*i, values.clone(), s)),
            Err(found) => issues.extend(found.into_iter().map(|mut is| {
                is.message = format!("{} (variant {i})", is.message);
                is
            })),
        }
    }
    if !issues.is_empty() {
        return Err(Error::InvalidScenario {
            path: source.to_path_buf(),
            issues,
        });
    }
    Ok(scenarios)
}

/// One solved (or failed) variant.
struct VariantOutcome {
    normal: Option<NormalSummary>,
    error: Option<Error>,
    fields: Vec<FieldSet>,
}

/// Run every variant of `text` (a scenario) over the Cartesian product of `vary`, in
/// parallel, and write one CSV row per variant into `out_dir`. By default each variant is the
/// normal-loading solve alone; with [`SweepOptions::runs`] each variant's whole scenario is
/// run into `out_dir/variant_NNNN/` (all the files of `fretsim run`), and without a shard the
/// fields of all variants are compared in `out_dir/plots/compare_*.svg` and `index.html`.
/// `on_variant` is called as each variant finishes (progress bars).
pub fn sweep(
    text: &str,
    source: &Path,
    vary: &[Vary],
    options: SweepOptions,
    out_dir: &Path,
    protected: &Protected,
    on_variant: &(dyn Fn() + Sync),
) -> Result<SweepOutput, Error> {
    let scenarios = sweep_variants(text, source, vary, options.shard)?;
    let name = match options.shard {
        Some(s) => format!("sweep-{}-of-{}.csv", s.index, s.count),
        None => "sweep.csv".to_string(),
    };
    let folder = SweepFolder::claim(out_dir, &name, protected)?;
    if options.runs {
        for (i, _, _) in &scenarios {
            RunFolder::check(&out_dir.join(variant_dir(*i)), protected)?;
        }
    }
    use rayon::prelude::*;
    let mut outcomes: Vec<VariantOutcome> = scenarios
        .par_iter()
        .map(|(i, _, sc)| {
            let outcome = if options.runs {
                let dir = out_dir.join(variant_dir(*i));
                let claimed = RunFolder::claim(&dir, protected);
                match claimed.and_then(|f| run_partial(sc, f, &mut crate::history::NoObserver)) {
                    // A history that stops part-way keeps its normal loading and the fields
                    // reached.
                    Ok((r, error)) => VariantOutcome {
                        normal: Some(r.summary.normal_loading),
                        error,
                        fields: r.fields,
                    },
                    Err(e) => VariantOutcome {
                        normal: None,
                        error: Some(e),
                        fields: Vec::new(),
                    },
                }
            } else {
                let disc = Discretisation::new(sc.collocation_points);
                match solve_normal(&sc.model, &disc, sc.normal_load, NormalOptions::default()) {
                    Ok(n) => VariantOutcome {
                        normal: Some(normal_summary(&sc.model, &n)),
                        error: None,
                        fields: Vec::new(),
                    },
                    Err(failure) => VariantOutcome {
                        normal: None,
                        error: Some(Error::Solve {
                            context: "normal loading".into(),
                            failure,
                        }),
                        fields: Vec::new(),
                    },
                }
            };
            on_variant();
            outcome
        })
        .collect();
    // An output folder that cannot be written stops the sweep (exit 2); solver failures are
    // reported per variant.
    if let Some(k) = outcomes.iter().position(|o| {
        matches!(
            o.error,
            Some(Error::WriteOutput { .. } | Error::OutputRefused { .. })
        )
    }) && let Some(e) = outcomes.swap_remove(k).error
    {
        return Err(e);
    }
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header = vec!["variant".to_string()];
    header.extend(vary.iter().map(|v| v.path.clone()));
    header.extend(
        [
            "a_m",
            "b_over_a",
            "C_per_m",
            "p0_Pa",
            "charge_C_per_m",
            "potential_V",
            "slip_sign_right",
            "error",
        ]
        .map(String::from),
    );
    w.write_record(&header).expect("in-memory write");
    for ((i, values, _), o) in scenarios.iter().zip(&outcomes) {
        let mut row = vec![i.to_string()];
        row.extend(values.iter().map(|x| format!("{x:.12e}")));
        match &o.normal {
            Some(n) => row.extend(
                [
                    n.half_width,
                    n.stick_ratio,
                    n.strain_slope,
                    n.peak_pressure,
                    n.charge,
                    n.potential.unwrap_or(f64::NAN),
                    n.right_slip_sign,
                ]
                .iter()
                .map(|x| format!("{x:.10e}")),
            ),
            None => row.extend(std::iter::repeat_n("NaN".to_string(), 7)),
        }
        row.push(o.error.as_ref().map(|e| e.to_string()).unwrap_or_default());
        w.write_record(&row).expect("in-memory write");
    }
    let csv_path = folder.dir().join(&name);
    crate::output::write_atomic(&csv_path, &w.into_inner().expect("in-memory write"))?;
    if options.runs && options.shard.is_none() {
        write_comparison(vary, &scenarios, &outcomes, out_dir, &name)?;
    }
    Ok(SweepOutput {
        csv: csv_path,
        variants: outcomes.len(),
        failed: outcomes.iter().filter(|o| o.error.is_some()).count(),
        failure_files: scenarios
            .iter()
            .zip(&outcomes)
            .filter(|(_, o)| options.runs && o.error.is_some())
            .map(|((i, _, _), _)| out_dir.join(variant_dir(*i)).join("failure.json"))
            .filter(|p| p.is_file())
            .collect(),
    })
}

/// The comparison plots of a sweep with runs: for the end of normal loading and each snapshot
/// instant, p, q, g, σxx0 and Dx0 with one curve per variant; and the sweep's `index.html`.
fn write_comparison(
    vary: &[Vary],
    scenarios: &[(usize, Vec<f64>, Scenario)],
    outcomes: &[VariantOutcome],
    out_dir: &Path,
    csv_name: &str,
) -> Result<(), Error> {
    let labels: Vec<String> = scenarios
        .iter()
        .map(|(_, values, _)| variant_label(vary, values))
        .collect();
    let mut stems = vec!["normal_loading".to_string()];
    if let Some((_, _, sc)) = scenarios.first() {
        stems.extend(
            sc.snapshots
                .iter()
                .map(|t| crate::scenario::snapshot_stem(*t)),
        );
    }
    let mut sections = Vec::new();
    for stem in &stems {
        let family: Vec<(&str, &[SurfacePoint])> = labels
            .iter()
            .zip(outcomes)
            .filter_map(|(label, o)| {
                let set = o.fields.iter().find(|f| &f.stem == stem)?;
                Some((label.as_str(), set.points.as_slice()))
            })
            .collect();
        let what = match scenarios.first() {
            Some((_, _, sc)) if stem != "normal_loading" => {
                let t = sc
                    .snapshots
                    .iter()
                    .find(|t| &crate::scenario::snapshot_stem(**t) == stem)
                    .copied()
                    .unwrap_or(f64::NAN);
                format!("at t = {t} s")
            }
            _ => "at the end of normal loading".to_string(),
        };
        let plots = family_plots(&format!("compare_{stem}"), &what, &family);
        let mut names = Vec::new();
        for (name, svg) in plots {
            crate::output::write_atomic(
                &out_dir.join("plots").join(format!("{name}.svg")),
                svg.as_bytes(),
            )?;
            names.push(name);
        }
        if !names.is_empty() {
            sections.push((format!("Fields {what}, by variant"), names));
        }
    }
    let mut files = vec![csv_name.to_string()];
    files.extend(
        scenarios
            .iter()
            .map(|(i, _, _)| format!("{}/index.html", variant_dir(*i))),
    );
    let name = scenarios
        .first()
        .map_or("sweep", |(_, _, sc)| sc.name.as_str());
    crate::output::write_atomic(
        &out_dir.join("index.html"),
        index_html(&format!("{name} (sweep)"), &sections, &files).as_bytes(),
    )
}

/// One fretting cycle: from a positive extreme of Q to the next.
#[derive(Debug, Clone, Serialize)]
pub struct CycleRow {
    /// Cycle number (1-based).
    pub cycle: usize,
    /// First and last step.
    pub steps: (usize, usize),
    /// Q at the start, the minimum and the end of the cycle (N/m).
    pub loads: (f64, f64, f64),
    /// Loop area ∮Q dδ (J/m), trapezoidal over the steps.
    pub loop_area: f64,
    /// Frictional work Σ −∫ q Δs (J/m).
    pub friction_work: f64,
    /// Work of the normal load over the cycle (J/m); zero over a closed cycle.
    pub normal_work: f64,
    /// Work of the electric load over the cycle (J/m).
    pub electric_work: f64,
    /// δ at the positive and at the negative extreme (m).
    pub displacement_extremes: (f64, f64),
    /// Stick-zone ends at the positive extreme (m).
    pub stick_at_max: (f64, f64),
    /// Stick-zone ends at the negative extreme (m).
    pub stick_at_min: (f64, f64),
    /// Largest change against the latest earlier cycle under the same loads (start, minimum
    /// and end of Q), relative (stick ends to a, δ to the δ amplitude, energy to the loop
    /// area); `None` when no earlier cycle had the same loads.
    pub change: Option<f64>,
    /// The cycle compared with.
    pub compared_with: Option<usize>,
}

/// Whether the cycles have settled.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Verdict {
    /// The response repeats within the tolerance from this cycle on.
    SteadyCyclicSlip {
        /// Every cycle after this one repeats the latest earlier cycle under the same loads
        /// (start, minimum and end of Q) within the tolerance.
        from_cycle: usize,
    },
    /// Slip has stopped: the dissipation per cycle vanishes.
    Shakedown {
        /// First cycle without dissipation.
        from_cycle: usize,
    },
    /// Still changing.
    NotSettled {
        /// Change of the last cycle against the one before.
        last_change: Option<f64>,
    },
    /// Fewer than one full cycle.
    NoCycles,
}

/// Split the records into cycles (positive extreme to positive extreme) and judge them.
pub fn analyse_cycles(
    records: &[crate::history::StepRecord],
    tolerance: f64,
) -> (Vec<CycleRow>, Verdict) {
    // Positive extremes: last step of a forward phase followed by a reverse phase.
    let maxima: Vec<usize> = (1..records.len().saturating_sub(1))
        .filter(|&i| {
            records[i].regime == crate::history::Regime::ForwardSlip
                && records[i + 1].regime == crate::history::Regime::ReverseSlip
        })
        .chain(
            (records.len() > 1
                && records
                    .last()
                    .is_some_and(|r| r.regime == crate::history::Regime::ForwardSlip))
            // Lazily: with no records `len() − 1` overflows (a panic in a debug build).
            .then(|| records.len() - 1),
        )
        .collect();
    let mut rows: Vec<CycleRow> = Vec::new();
    let load_scale = records.iter().map(|r| r.q.abs()).fold(0.0, f64::max);
    for (k, w) in maxima.windows(2).enumerate() {
        let seg = &records[w[0]..=w[1]];
        let area = seg
            .windows(2)
            .map(|p| 0.5 * (p[0].q + p[1].q) * (p[1].displacement - p[0].displacement))
            .sum();
        let work = seg[1..].iter().map(|r| r.dissipation).sum();
        let normal_work = seg[1..].iter().map(|r| r.normal_work).sum();
        let electric_work = seg[1..].iter().map(|r| r.electric_work).sum();
        let min = seg
            .iter()
            .min_by(|a, b| a.q.total_cmp(&b.q))
            .expect("non-empty");
        let (hi_rec, lo_rec) = (&seg[seg.len() - 1], min);
        let mut row = CycleRow {
            cycle: k + 1,
            steps: (seg[0].step, hi_rec.step),
            loads: (seg[0].q, lo_rec.q, hi_rec.q),
            loop_area: area,
            friction_work: work,
            normal_work,
            electric_work,
            displacement_extremes: (hi_rec.displacement, lo_rec.displacement),
            stick_at_max: (hi_rec.stick_lo, hi_rec.stick_hi),
            stick_at_min: (lo_rec.stick_lo, lo_rec.stick_hi),
            change: None,
            compared_with: None,
        };
        // Compare with the latest earlier cycle under the same loads (start, minimum, end):
        // the previous cycle under constant amplitude, the same cycle one block earlier under
        // a repeated variable-amplitude block.
        let same = |a: (f64, f64, f64), b: (f64, f64, f64)| {
            let tol = 1e-9 * load_scale;
            (a.0 - b.0).abs() <= tol && (a.1 - b.1).abs() <= tol && (a.2 - b.2).abs() <= tol
        };
        if let Some(prev) = rows.iter().rev().find(|r| same(r.loads, row.loads)) {
            let a = hi_rec.half_width;
            let amp = (prev.displacement_extremes.0 - prev.displacement_extremes.1)
                .abs()
                .max(1e-300);
            let energy = prev.loop_area.abs().max(1e-300);
            let d = [
                (row.stick_at_max.0 - prev.stick_at_max.0).abs() / a,
                (row.stick_at_max.1 - prev.stick_at_max.1).abs() / a,
                (row.stick_at_min.0 - prev.stick_at_min.0).abs() / a,
                (row.stick_at_min.1 - prev.stick_at_min.1).abs() / a,
                (row.displacement_extremes.0 - prev.displacement_extremes.0).abs() / amp,
                (row.displacement_extremes.1 - prev.displacement_extremes.1).abs() / amp,
                (row.loop_area - prev.loop_area).abs() / energy,
            ];
            row.change = Some(d.into_iter().fold(0.0, f64::max));
            row.compared_with = Some(prev.cycle);
        }
        rows.push(row);
    }
    let verdict = if rows.is_empty() {
        Verdict::NoCycles
    } else if let Some(r) = rows.iter().find(|r| {
        let amp = (r.displacement_extremes.0 - r.displacement_extremes.1).abs();
        r.loop_area.abs() <= tolerance * amp * load_scale
    }) {
        Verdict::Shakedown {
            from_cycle: r.cycle,
        }
    } else {
        // Steady from cycle k when every later cycle repeats the latest earlier cycle under
        // the same loads (and at least one does).
        let repeats = |r: &CycleRow| r.change.is_some_and(|c| c <= tolerance);
        let first_steady = (1..rows.len())
            .find(|&i| rows[i..].iter().all(repeats))
            .map(|i| rows[i - 1].cycle);
        match first_steady {
            Some(from_cycle) => Verdict::SteadyCyclicSlip { from_cycle },
            None => Verdict::NotSettled {
                last_change: rows.last().and_then(|r| r.change),
            },
        }
    };
    (rows, verdict)
}
