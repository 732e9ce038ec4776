//! Orchestration: scenario → model → normal loading → outputs. No physics here.

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::contact::normal::{NormalLoading, NormalOptions, solve_normal};
use crate::contact::pressure::Discretisation;
use crate::contact::tangential::SlipOptions;
use crate::contact::{ContactModel, SurfacePoint};
use crate::error::Error;
use crate::halfplane::{PaperCoefficients, SurfaceCompliance, SurfaceFieldCoefficients};
use crate::output::{Staging, csv_bytes};
use crate::scenario::{RawScenario, Scenario};

/// Constants derived from the material, reported in `summary.json`.
#[derive(Debug, Serialize)]
pub struct Derived {
    /// Surface compliance coefficients (fretsim's convention).
    pub compliance: SurfaceCompliance,
    /// The same in the seed paper's convention (Appendix A.2).
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
    /// Normal-loading results.
    pub normal_loading: NormalSummary,
    /// Tangential history results (absent without a history).
    pub history: Option<HistorySummary>,
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
    let w_total = s.potential_charge.integral() * s.half_width;
    NormalSummary {
        half_width: s.half_width,
        eccentricity: -s.centre,
        stick_half_width: n.stick_half_width,
        stick_ratio: n.stick_half_width / s.half_width,
        strain_slope: n.strain_slope,
        peak_pressure: s.pressure_at(s.centre),
        charge: s.charge,
        potential: s.potential,
        pressure_resultant: s.pressure.integral() * s.half_width,
        // The inverse-square-root part integrates exactly from its series; the rest by quadrature.
        charge_resultant: s.split.ratio * s.pressure.integral() * s.half_width + w_total,
        iterations: n.iterations,
        admissibility: n.admissibility,
        outside_gap: model.outside_gap(s),
        pressure_charge: model.pressure_charge(s.normal_load),
    }
}

/// Solve a validated scenario and write its outputs into `out_dir` (replacing it).
pub fn run(scenario: &Scenario, out_dir: &Path) -> Result<RunResult, Error> {
    run_with(scenario, out_dir, &mut crate::history::NoObserver)
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

/// As [`run`], reporting each accepted step to `observer` (progress bars).
pub fn run_with(
    scenario: &Scenario,
    out_dir: &Path,
    observer: &mut dyn crate::history::Observer,
) -> Result<RunResult, Error> {
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
    let history_summary = scenario.history.as_ref().map(|_| {
        let turning_points = records
            .windows(2)
            .filter(|w| w[0].phase != w[1].phase && w[0].phase > 0)
            .map(|w| w[0].clone())
            .chain(records.last().filter(|r| r.phase > 0).cloned())
            .collect();
        let tolerance = scenario.raw.numerics.cycle_tolerance;
        let (cycles, verdict) = analyse_cycles(&records, tolerance);
        HistorySummary {
            steps: records.len().saturating_sub(1),
            phases: records.last().map_or(0, |r| r.phase),
            turning_points,
            failure: failure.as_ref().map(|e| e.to_string()),
            cycles,
            verdict,
            verdict_tolerance: tolerance,
        }
    });
    let summary = Summary {
        fretsim_version: env!("CARGO_PKG_VERSION"),
        scenario: scenario.raw.clone(),
        derived: derived(model, scenario.normal_load),
        normal_loading: normal_summary(model, &normal),
        history: history_summary,
        warnings,
    };
    let points: Vec<SurfacePoint> = field_points(normal.state.centre, normal.state.half_width, 400)
        .into_iter()
        .map(|x| model.surface_point(&normal.state, x))
        .collect();
    let staging = Staging::new(out_dir)?;
    let result = (|| {
        staging.write(
            "summary.json",
            &serde_json::to_vec_pretty(&summary).expect("summary serialises"),
        )?;
        staging.write("fields/normal_loading.csv", &fields_csv(&points))?;
        if scenario.history.is_some() {
            staging.write(
                "steps.csv",
                &steps_csv(&records, model.friction * scenario.normal_load),
            )?;
            staging.write(
                "cycles.csv",
                &cycles_csv(&analyse_cycles(&records, scenario.raw.numerics.cycle_tolerance).0),
            )?;
        }
        // Fields at the turning points of the history and at its last step.
        let mut turning: Vec<&(crate::history::StepRecord, crate::contact::ContactState)> =
            snapshots.kept.iter().collect();
        if let Some(last) = &snapshots.previous {
            turning.push(last);
        }
        for (rec, state) in turning {
            let points: Vec<SurfacePoint> = field_points(state.centre, state.half_width, 400)
                .into_iter()
                .map(|x| model.surface_point(state, x))
                .collect();
            staging.write(
                &format!("fields/step_{:05}.csv", rec.step),
                &fields_csv(&points),
            )?;
        }
        for (name, svg) in plots(&points, &records, model.friction * scenario.normal_load) {
            staging.write(&format!("plots/{name}.svg"), svg.as_bytes())?;
        }
        staging.write(
            "index.html",
            index_html(&scenario.name, &records).as_bytes(),
        )?;
        if let Some(e) = &failure {
            let body = serde_json::json!({
                "error": e.to_string(),
                "last_accepted_step": records.last(),
            });
            staging.write(
                "failure.json",
                &serde_json::to_vec_pretty(&body).expect("serialises"),
            )?;
        }
        Ok::<(), Error>(())
    })();
    match result {
        Ok(()) => {
            let out_dir = staging.commit()?;
            match failure {
                Some(e) => Err(e),
                None => Ok(RunResult { out_dir, summary }),
            }
        }
        Err(e) => {
            staging.abandon();
            Err(e)
        }
    }
}

/// Forwards steps to the caller's observer and keeps the states at the turning points (the
/// last step of each phase) for the field files.
struct Snapshots<'a> {
    inner: &'a mut dyn crate::history::Observer,
    previous: Option<(crate::history::StepRecord, crate::contact::ContactState)>,
    kept: Vec<(crate::history::StepRecord, crate::contact::ContactState)>,
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
        self.inner.on_step(record, state);
    }

    fn on_phase(&mut self, phase: usize, memory: &crate::contact::memory::Memory) {
        self.inner.on_phase(phase, memory);
    }
}

/// The SVG plots of a run: fields at the end of normal loading, and with a history the
/// hysteresis loop and the stick-zone ends.
fn plots(
    points: &[SurfacePoint],
    records: &[crate::history::StepRecord],
    limit: f64,
) -> Vec<(&'static str, String)> {
    use crate::plot::{Series, line_plot};
    let field =
        |f: &dyn Fn(&SurfacePoint) -> f64| points.iter().map(|p| (p.x, f(p))).collect::<Vec<_>>();
    let mut out = vec![
        (
            "normal_loading_tractions",
            line_plot(
                "End of normal loading: pressure and shear traction",
                "x (m)",
                "Pa",
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
        (
            "normal_loading_charge",
            line_plot(
                "End of normal loading: surface charge g",
                "x (m)",
                "C/m²",
                &[Series {
                    label: "g",
                    points: field(&|p| p.charge),
                    colour: "navy",
                }],
            ),
        ),
        (
            "normal_loading_sigma_xx",
            line_plot(
                "End of normal loading: surface stress σxx0",
                "x (m)",
                "Pa",
                &[Series {
                    label: "σxx0",
                    points: field(&|p| p.sigma_xx),
                    colour: "darkgreen",
                }],
            ),
        ),
        (
            "normal_loading_d_x",
            line_plot(
                "End of normal loading: in-plane electric displacement Dx0",
                "x (m)",
                "C/m²",
                &[Series {
                    label: "Dx0",
                    points: field(&|p| p.d_x),
                    colour: "purple",
                }],
            ),
        ),
    ];
    if records.len() > 1 {
        let loop_pts: Vec<(f64, f64)> = records
            .iter()
            .map(|r| (r.displacement, r.q / limit))
            .collect();
        out.push((
            "hysteresis",
            line_plot(
                "Fretting loop",
                "tangential displacement δ (m)",
                "Q/(ηP)",
                &[Series {
                    label: "Q–δ",
                    points: loop_pts,
                    colour: "black",
                }],
            ),
        ));
        let ends = |f: &dyn Fn(&crate::history::StepRecord) -> f64| {
            records
                .iter()
                .map(|r| (r.step as f64, f(r) / r.half_width))
                .collect::<Vec<_>>()
        };
        out.push((
            "stick_zone",
            line_plot(
                "Stick-zone ends and contact ends",
                "step",
                "x / a",
                &[
                    Series {
                        label: "stick left end",
                        points: ends(&|r| r.stick_lo),
                        colour: "navy",
                    },
                    Series {
                        label: "stick right end",
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
        ));
    }
    out
}

/// `index.html`: all plots on one page.
fn index_html(name: &str, records: &[crate::history::StepRecord]) -> String {
    let mut names = vec![
        "normal_loading_tractions",
        "normal_loading_charge",
        "normal_loading_sigma_xx",
        "normal_loading_d_x",
    ];
    if records.len() > 1 {
        names.extend(["hysteresis", "stick_zone"]);
    }
    let imgs: String = names
        .iter()
        .map(|n| format!("<figure><img src=\"plots/{n}.svg\" alt=\"{n}\"></figure>\n"))
        .collect();
    format!(
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>fretsim: {name}</title></head>\n<body>\n<h1>fretsim: {name}</h1>\n<p>Files: summary.json, fields/normal_loading.csv, steps.csv, cycles.csv (see README).</p>\n{imgs}</body></html>\n"
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
    let rows: Vec<Vec<f64>> = cycles
        .iter()
        .map(|c| {
            vec![
                c.cycle as f64,
                c.steps.0 as f64,
                c.steps.1 as f64,
                c.loop_area,
                c.friction_work,
                c.normal_work,
                c.electric_work,
                c.displacement_extremes.0,
                c.displacement_extremes.1,
                c.stick_at_max.0,
                c.stick_at_max.1,
                c.stick_at_min.0,
                c.stick_at_min.1,
                c.change.unwrap_or(f64::NAN),
            ]
        })
        .collect();
    csv_bytes(
        &[
            "cycle",
            "first_step",
            "last_step",
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
        ],
        &rows,
    )
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

fn set_path(value: &mut serde_json::Value, path: &str, x: f64) -> Result<(), String> {
    let mut cur = value;
    let keys: Vec<&str> = path.split('.').collect();
    for (i, k) in keys.iter().enumerate() {
        let obj = cur
            .as_object_mut()
            .ok_or_else(|| format!("`{path}`: `{}` is not an object", keys[..i].join(".")))?;
        if i + 1 == keys.len() {
            obj.insert((*k).to_string(), serde_json::json!(x));
            return Ok(());
        }
        cur = obj
            .entry((*k).to_string())
            .or_insert_with(|| serde_json::json!({}));
    }
    Ok(())
}

/// Run the normal-loading solve for every variant of `text` (a scenario) over the Cartesian
/// product of `vary`, in parallel, and return the CSV bytes of one row per variant.
pub fn sweep(
    text: &str,
    source: &Path,
    vary: &[Vary],
    shard: Option<Shard>,
) -> Result<Vec<u8>, Error> {
    let base: serde_json::Value = serde_json::from_str(text).map_err(|e| Error::ParseScenario {
        path: source.to_path_buf(),
        at: String::new(),
        line: e.line(),
        column: e.column(),
        message: e.to_string(),
    })?;
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
    // Validate every variant before solving any.
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
    use rayon::prelude::*;
    let rows: Vec<Vec<String>> = scenarios
        .par_iter()
        .map(|(i, values, sc)| {
            let disc = Discretisation::new(sc.collocation_points);
            let mut row = vec![i.to_string()];
            row.extend(values.iter().map(|x| format!("{x:.12e}")));
            match solve_normal(&sc.model, &disc, sc.normal_load, NormalOptions::default()) {
                Ok(n) => {
                    let s = &n.state;
                    row.extend(
                        [
                            s.half_width,
                            n.stick_half_width / s.half_width,
                            n.strain_slope,
                            s.pressure_at(s.centre),
                            s.charge,
                            s.potential.unwrap_or(f64::NAN),
                            s.traction.right_sign,
                        ]
                        .iter()
                        .map(|x| format!("{x:.10e}")),
                    );
                    row.push(String::new());
                }
                Err(e) => {
                    row.extend(std::iter::repeat_n("NaN".to_string(), 7));
                    row.push(e.to_string());
                }
            }
            row
        })
        .collect();
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
    for r in rows {
        w.write_record(&r).expect("in-memory write");
    }
    Ok(w.into_inner().expect("in-memory write"))
}

/// One fretting cycle: from a positive extreme of Q to the next.
#[derive(Debug, Clone, Serialize)]
pub struct CycleRow {
    /// Cycle number (1-based).
    pub cycle: usize,
    /// First and last step.
    pub steps: (usize, usize),
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
    /// Largest change against the previous cycle, relative (stick ends to a, δ to the δ
    /// amplitude, energy to the loop area); `None` for the first cycle.
    pub change: Option<f64>,
}

/// Whether the cycles have settled.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Verdict {
    /// The response repeats within the tolerance from this cycle on.
    SteadyCyclicSlip {
        /// First cycle of the repeating sequence (every later cycle repeats it).
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
            .then_some(records.len() - 1),
        )
        .collect();
    let mut rows: Vec<CycleRow> = Vec::new();
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
            loop_area: area,
            friction_work: work,
            normal_work,
            electric_work,
            displacement_extremes: (hi_rec.displacement, lo_rec.displacement),
            stick_at_max: (hi_rec.stick_lo, hi_rec.stick_hi),
            stick_at_min: (lo_rec.stick_lo, lo_rec.stick_hi),
            change: None,
        };
        if let Some(prev) = rows.last() {
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
        }
        rows.push(row);
    }
    let verdict = if rows.is_empty() {
        Verdict::NoCycles
    } else if let Some(r) = rows.iter().find(|r| {
        let amp = (r.displacement_extremes.0 - r.displacement_extremes.1).abs();
        let load = records.iter().map(|x| x.q.abs()).fold(0.0, f64::max);
        r.loop_area.abs() <= tolerance * amp * load
    }) {
        Verdict::Shakedown {
            from_cycle: r.cycle,
        }
    } else {
        // Steady from cycle k when every later cycle repeats its predecessor.
        // `from_cycle` is the first cycle of the repeating sequence.
        let first_steady = (1..rows.len())
            .find(|&i| {
                rows[i..]
                    .iter()
                    .all(|r| r.change.is_some_and(|c| c <= tolerance))
            })
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
