//! `fretsim sweep`: the Cartesian product of linear ranges of scenario fields, solved in
//! parallel, one CSV row per variant; with runs, every variant's whole output and the fields of
//! all variants compared in one plot per quantity and instant.

use std::path::{Path, PathBuf};

use crate::contact::pressure::Discretisation;
use crate::error::Error;
use crate::io::folder::{Protected, RunFolder, SweepFolder};
use crate::io::plots::{FamilyMember, PlotScales, family_plots, index_html};
use crate::io::run::{FieldSet, run_resumed};
use crate::io::summary::{NormalSummary, normal_summary};
use crate::io::sweep_plots::{ResultColumn, sweep_plots};
use crate::scenario::Scenario;

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
pub(crate) fn is_integer_field(path: &str) -> bool {
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
pub(crate) fn field_value(path: &str, x: f64) -> Result<serde_json::Value, String> {
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

pub(crate) fn set_path(value: &mut serde_json::Value, path: &str, x: f64) -> Result<(), String> {
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

    /// A shard runs the variants i with i mod N = I − 1: counted without listing them, and
    /// the product of the counts without overflow.
    #[test]
    fn shard_and_variant_counts() {
        for total in 0..20 {
            for count in 1..6 {
                for index in 1..=count {
                    let listed = (0..total).filter(|i| i % count == index - 1).count();
                    let shard = Some(Shard { index, count });
                    assert_eq!(shard_count(total, shard), listed, "{total} {index}/{count}");
                }
            }
            assert_eq!(shard_count(total, None), total);
        }
        let wide: Vary = "friction=0:1:100000".parse().unwrap();
        let err = variant_count(&[wide.clone(), wide.clone(), wide], Path::new("s.json"));
        assert!(
            err.unwrap_err()
                .to_string()
                .contains("100000 × 100000 × 100000 variants")
        );
    }

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
pub(crate) fn variant_label(vary: &[Vary], values: &[f64]) -> String {
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

/// The number of variants of a sweep (the product of the ranges' counts), or an input error
/// when it exceeds [`MAX_SWEEP_VARIANTS`].
pub fn variant_count(vary: &[Vary], source: &Path) -> Result<usize, Error> {
    vary.iter()
        .try_fold(1usize, |n, v| n.checked_mul(v.values.len()))
        .filter(|&n| n <= MAX_SWEEP_VARIANTS)
        .ok_or_else(|| {
            let counts: Vec<String> = vary.iter().map(|v| v.values.len().to_string()).collect();
            Error::InvalidScenario {
                path: source.to_path_buf(),
                issues: vec![crate::error::Issue::new(
                    "--vary",
                    format!(
                        "{} variants is invalid; it must be at most {MAX_SWEEP_VARIANTS}",
                        counts.join(" × ")
                    ),
                )],
            }
        })
}

/// The variants that shard `shard` of a sweep of `total` runs: every N-th from the I-th.
pub fn shard_count(total: usize, shard: Option<Shard>) -> usize {
    shard.map_or(total, |s| {
        total.saturating_sub(s.index - 1).div_ceil(s.count)
    })
}

/// The scenario variants of a sweep: every point of the Cartesian product of `vary` (in the
/// shard), validated before any is solved.
pub(crate) fn sweep_variants(
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
    variant_count(vary, source)?;
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
pub(crate) struct VariantOutcome {
    normal: Option<NormalSummary>,
    error: Option<Error>,
    fields: Vec<FieldSet>,
    /// The history's results (a sweep with runs, a scenario with a history).
    history: Option<HistoryColumns>,
}

/// A variant's history in `sweep.csv` (sweeps with runs): steps, cycles, the verdict, the
/// last full cycle's friction work, displacement amplitude, regime, slip amplitude and energy
/// ratio ([`crate::analysis::CycleRow`]), and the steps the general solver took.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct HistoryColumns {
    steps: usize,
    cycles: usize,
    verdict: String,
    friction_work: f64,
    displacement_amplitude: f64,
    /// The last cycle's regime (`partial_slip`, `gross_slip`, `no_slip`; empty without one).
    regime: String,
    slip_amplitude: f64,
    energy_ratio: f64,
    general_steps: usize,
}

impl HistoryColumns {
    const HEADER: [&'static str; 9] = [
        "steps",
        "cycles",
        "verdict",
        "friction_work_last_cycle_J_per_m",
        "delta_amplitude_last_cycle_m",
        "regime_last_cycle",
        "slip_amplitude_last_cycle_m",
        "energy_ratio_last_cycle",
        "general_steps",
    ];

    fn of(summary: &crate::io::summary::Summary) -> Option<Self> {
        let h = summary.history.as_ref()?;
        let last = h.cycles.last();
        let verdict = serde_json::to_value(&h.verdict)
            .ok()
            .and_then(|v| v.get("kind").and_then(|k| k.as_str()).map(String::from))
            .unwrap_or_default();
        Some(Self {
            steps: h.steps,
            cycles: h.cycle_count,
            verdict,
            friction_work: last.map_or(f64::NAN, |c| c.friction_work),
            displacement_amplitude: last.map_or(f64::NAN, |c| {
                0.5 * (c.displacement_extremes.0 - c.displacement_extremes.1)
            }),
            regime: last
                .and_then(|c| serde_json::to_value(c.regime).ok())
                .and_then(|v| v.as_str().map(String::from))
                .unwrap_or_default(),
            slip_amplitude: last.and_then(|c| c.slip_amplitude).unwrap_or(f64::NAN),
            energy_ratio: last.and_then(|c| c.energy_ratio).unwrap_or(f64::NAN),
            general_steps: summary.solver.general_steps,
        })
    }

    fn cells(history: Option<&Self>) -> Vec<String> {
        match history {
            Some(h) => vec![
                h.steps.to_string(),
                h.cycles.to_string(),
                h.verdict.clone(),
                format!("{:.10e}", h.friction_work),
                format!("{:.10e}", h.displacement_amplitude),
                h.regime.clone(),
                format!("{:.10e}", h.slip_amplitude),
                format!("{:.10e}", h.energy_ratio),
                h.general_steps.to_string(),
            ],
            None => vec![String::new(); Self::HEADER.len()],
        }
    }
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
                match claimed.and_then(|f| run_resumed(sc, f, None, &mut crate::history::NoObserver)) {
                    // A history that stops part-way keeps its normal loading and the fields
                    // reached.
                    Ok(r) => VariantOutcome {
                        history: HistoryColumns::of(&r.solution.summary),
                        normal: Some(r.solution.summary.normal_loading),
                        error: r.solution.failure,
                        fields: r.solution.fields,
                    },
                    Err(e) => VariantOutcome {
                        normal: None,
                        error: Some(e),
                        fields: Vec::new(),
                        history: None,
                    },
                }
            } else {
                let disc = Discretisation::new(sc.collocation_points);
                match crate::history::NormalEnd::solve(
                    &sc.model,
                    &disc,
                    sc.normal_load,
                    sc.solver,
                    sc.raw.numerics.general_element_size,
                ) {
                    Ok(n) => VariantOutcome {
                        normal: Some(normal_summary(&sc.model, &n)),
                        error: None,
                        fields: Vec::new(),
                        history: None,
                    },
                    Err(failure) => VariantOutcome {
                        normal: None,
                        error: Some(Error::Solve {
                            context: "normal loading".into(),
                            failure,
                        }),
                        fields: Vec::new(),
                        history: None,
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
        ]
        .map(String::from),
    );
    if options.runs {
        header.extend(HistoryColumns::HEADER.map(String::from));
    }
    header.push("error".to_string());
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
        if options.runs {
            row.extend(HistoryColumns::cells(o.history.as_ref()));
        }
        row.push(o.error.as_ref().map(|e| e.to_string()).unwrap_or_default());
        w.write_record(&row).expect("in-memory write");
    }
    let csv_path = folder.dir().join(&name);
    crate::io::folder::write_atomic(&csv_path, &w.into_inner().expect("in-memory write"))?;
    if options.shard.is_none() {
        write_pages(vary, &scenarios, &outcomes, out_dir, &name, options.runs)?;
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

/// The numeric result columns of `sweep.csv` (the history's with runs), one value per
/// variant, for the result plots.
fn result_columns(outcomes: &[VariantOutcome], runs: bool) -> Vec<ResultColumn> {
    type Normal = fn(&NormalSummary) -> f64;
    let normal: [(&str, &str, Normal); 7] = [
        ("a_m", "contact half-width a (m)", |n| n.half_width),
        ("b_over_a", "stick ratio b/a (–)", |n| n.stick_ratio),
        ("C_per_m", "C (1/m)", |n| n.strain_slope),
        ("p0_Pa", "peak pressure p0 (Pa)", |n| n.peak_pressure),
        ("charge_C_per_m", "charge Γ (C/m)", |n| n.charge),
        ("potential_V", "potential φ0 (V)", |n| {
            n.potential.unwrap_or(f64::NAN)
        }),
        ("slip_sign_right", "slip sign, right zone (–)", |n| {
            n.right_slip_sign
        }),
    ];
    let mut columns: Vec<ResultColumn> = normal
        .iter()
        .map(|(name, label, f)| ResultColumn {
            name,
            label,
            values: outcomes
                .iter()
                .map(|o| o.normal.as_ref().map_or(f64::NAN, f))
                .collect(),
        })
        .collect();
    if runs {
        type History = fn(&HistoryColumns) -> f64;
        let history: [(&str, &str, History); 7] = [
            ("steps", "steps (–)", |h| h.steps as f64),
            ("cycles", "cycles (–)", |h| h.cycles as f64),
            (
                "friction_work_last_cycle_J_per_m",
                "friction work of the last cycle (J/m)",
                |h| h.friction_work,
            ),
            (
                "delta_amplitude_last_cycle_m",
                "δ amplitude of the last cycle (m)",
                |h| h.displacement_amplitude,
            ),
            (
                "slip_amplitude_last_cycle_m",
                "slip amplitude of the last cycle (m)",
                |h| h.slip_amplitude,
            ),
            (
                "energy_ratio_last_cycle",
                "energy ratio W/(4Q*δ*) of the last cycle (–)",
                |h| h.energy_ratio,
            ),
            ("general_steps", "steps of the general solver (–)", |h| {
                h.general_steps as f64
            }),
        ];
        columns.extend(history.iter().map(|(name, label, f)| {
            ResultColumn {
                name,
                label,
                values: outcomes
                    .iter()
                    .map(|o| o.history.as_ref().map_or(f64::NAN, f))
                    .collect(),
            }
        }));
    }
    columns
}

/// A sweep's pages: the plots of its scalar results (one varied field: against it; two: maps),
/// with runs the comparison plots of the fields, and `index.html`, which opens with a
/// contents list.
pub(crate) fn write_pages(
    vary: &[Vary],
    scenarios: &[(usize, Vec<f64>, Scenario)],
    outcomes: &[VariantOutcome],
    out_dir: &Path,
    csv_name: &str,
    runs: bool,
) -> Result<(), Error> {
    // PNG files as the scenario asks (the variants share the output options).
    let png = scenarios.first().is_none_or(|(_, _, sc)| sc.raw.output.png);
    let write = |plots: Vec<(String, String)>| -> Result<Vec<String>, Error> {
        use rayon::prelude::*;
        let files = plots
            .par_iter()
            .map(|(name, svg)| crate::io::png::plot_files(name, svg, png))
            .collect::<Result<Vec<_>, Error>>()?;
        for (path, bytes) in files.into_iter().flatten() {
            crate::io::folder::write_atomic(&out_dir.join(path), &bytes)?;
        }
        Ok(plots.into_iter().map(|(name, _)| name).collect())
    };
    let fields: Vec<&str> = vary.iter().map(|v| v.path.as_str()).collect();
    let axes: Vec<Vec<f64>> = vary.iter().map(|v| v.values.clone()).collect();
    let values: Vec<Vec<f64>> = scenarios.iter().map(|(_, v, _)| v.clone()).collect();
    // The categorical results (sweeps with runs): the verdict, and the last cycle's regime
    // (with the energy ratio's map beside it: a fretting map).
    let category = |of: fn(&HistoryColumns) -> &str| -> Vec<String> {
        outcomes
            .iter()
            .map(|o| match (&o.error, &o.history) {
                (Some(_), _) => "failed".to_string(),
                (None, Some(h)) if of(h).is_empty() => "no cycles".to_string(),
                (None, Some(h)) => of(h).to_string(),
                (None, None) => "no history".to_string(),
            })
            .collect()
    };
    let categories: Vec<(&str, Vec<String>)> = if runs {
        vec![
            ("verdict", category(|h| &h.verdict)),
            ("regime", category(|h| &h.regime)),
        ]
    } else {
        Vec::new()
    };
    let results = sweep_plots(
        &fields,
        &axes,
        &values,
        &result_columns(outcomes, runs),
        &categories,
    );
    let title = match fields.as_slice() {
        [f] => format!("Results against {f}"),
        [f0, f1] => format!("Maps over {f0} × {f1}"),
        _ => String::new(),
    };
    let mut sections = Vec::new();
    let names = write(results)?;
    if !names.is_empty() {
        sections.push((title, names));
    }
    if runs {
        sections.extend(comparison_plots(vary, scenarios, outcomes, &write)?);
    }
    let mut files = vec![csv_name.to_string()];
    if runs {
        files.extend(
            scenarios
                .iter()
                .map(|(i, _, _)| format!("{}/index.html", variant_dir(*i))),
        );
    }
    let name = scenarios
        .first()
        .map_or("sweep", |(_, _, sc)| sc.name.as_str());
    crate::io::folder::write_atomic(
        &out_dir.join("index.html"),
        index_html(&format!("{name} (sweep)"), &sections, &files).as_bytes(),
    )
}

/// The comparison plots of a sweep with runs, written by `write`: for the end of normal
/// loading and each snapshot instant, p, q, g, σxx0 and Dx0 with one curve per variant; one
/// page section per instant.
fn comparison_plots(
    vary: &[Vary],
    scenarios: &[(usize, Vec<f64>, Scenario)],
    outcomes: &[VariantOutcome],
    write: &dyn Fn(Vec<(String, String)>) -> Result<Vec<String>, Error>,
) -> Result<Vec<(String, Vec<String>)>, Error> {
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
        let family: Vec<FamilyMember> = labels
            .iter()
            .zip(outcomes)
            .filter_map(|(label, o)| {
                let set = o.fields.iter().find(|f| &f.stem == stem)?;
                Some((label.as_str(), set.points.as_slice(), set.ends))
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
        // Variants differ in a and p0: their fields are compared in SI units.
        let plots = family_plots(&format!("compare_{stem}"), &what, &family, &PlotScales::SI);
        let names = write(plots)?;
        if !names.is_empty() {
            sections.push((format!("Fields {what}, by variant"), names));
        }
    }
    Ok(sections)
}
