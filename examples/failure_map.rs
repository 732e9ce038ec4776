//! The failure map of issue 37: which valid scenarios complete under `numerics.solver = auto`,
//! which ones the spectral solver alone fails, and, for every run the general solver took over,
//! how many steps it took and why.
//!
//! ```sh
//! cargo run --release --example failure_map -- output/failure_map --runs 200 --seed 1
//! cargo run --release --example failure_map -- output/failure_map --runs 2000 --seed 2 --budget-min 70
//! cargo run --release --example failure_map -- output/failure_map --summarise
//! ```
//!
//! The grid is the product of the axes below ([`MATERIALS`], [`FRICTIONS`], [`AMPLITUDES`],
//! [`KINDS`], [`STEPS_PER_SEGMENT`], [`MAX_STEPS`], [`COLLOCATION`], and three seeds for the
//! random variable-amplitude history), about 35,000 runs: far more than an afternoon. Each
//! invocation draws `--runs` scenarios from it with balanced marginals (every axis value is
//! drawn equally often, the combinations at random, seeded), skips the runs already in the
//! folder's `results.csv`, and runs them one after another on one thread until `--budget-min`
//! minutes have passed. Random variable-amplitude histories and 40 steps per segment are the
//! expensive ones; their shares are capped (`--random-share`, `--fine-share`).
//!
//! Each scenario is written as the JSON text a user would write and goes through
//! `fretsim::parse` and `fretsim::validate`; the ones the validator rejects are listed in
//! `rejected.csv`, not run. A valid one runs with `auto` under a wall-time cap (`--cap-s`, the
//! run is abandoned at the first step after it: "timeout") and with `spectral` under a smaller
//! cap (`--spectral-cap-s`). One row per run goes to `results.csv`, flushed as it is written;
//! `summary.md` is rewritten from `results.csv` at the end (or with `--summarise`).
//! `--only FILE` runs only the drawn points whose ids the file lists, one a line: the timeouts
//! of a draw, for example, again with a longer cap into another folder.
//!
//! The example writes files, so it is not the numerical core: it only calls
//! `fretsim::parse`, `fretsim::validate` and `fretsim::solve`.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::fs;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use fretsim::SolveFailure;
use fretsim::history::{Observer, SolverKind, StateView, StepFailure, StepRecord};
use serde::{Deserialize, Serialize};

/// A half-plane and its punch: material, electrode, and the load and radius they are used at.
#[derive(Debug, Clone, Copy)]
struct MaterialCase {
    /// Label in the CSV.
    label: &'static str,
    /// Family, for the per-material table.
    family: &'static str,
    /// `material` JSON.
    material: &'static str,
    /// Electrode.
    electrode: ElectrodeCase,
    /// Punch radius R (m).
    radius: f64,
    /// Normal load P (N/m).
    normal_load: f64,
}

/// The electric boundary condition of a case.
#[derive(Debug, Clone, Copy)]
enum ElectrodeCase {
    /// Elastic half-plane, no electrode.
    None,
    /// Insulating punch.
    Insulating,
    /// Conducting punch at charge Γ (C/m).
    Charge(f64),
    /// Conducting punch at charge Γ = factor × Γ1 (Γ1 = kP).
    ChargeOfGamma1(f64),
    /// Conducting punch at the potential φ0 that Γ = factor × Γ1 gives in normal loading.
    PotentialOfGamma1(f64),
    /// Conducting punch at the potential φ0 that Γ (C/m) gives in normal loading.
    PotentialOfCharge(f64),
    /// Conducting punch at potential φ0 (V).
    Potential(f64),
}

const PZT4: &str = r#"{ "kind": "preset", "name": "pzt4" }"#;
const PZT5H: &str = r#"{ "kind": "preset", "name": "pzt5h" }"#;
const ALUMINIUM: &str = r#"{ "kind": "preset", "name": "aluminium" }"#;
const NU_HALF: &str = r#"{ "kind": "elastic", "shear_modulus": 27.3e9, "poisson_ratio": 0.5 }"#;

/// The material axis.
const MATERIALS: [MaterialCase; 10] = [
    pzt(
        "pzt4_charge_2e-7",
        "pzt4 conducting",
        PZT4,
        ElectrodeCase::Charge(2e-7),
    ),
    pzt(
        "pzt4_charge_6e-7",
        "pzt4 conducting",
        PZT4,
        ElectrodeCase::Charge(6e-7),
    ),
    pzt(
        "pzt4_charge_1.5G1",
        "pzt4 conducting",
        PZT4,
        ElectrodeCase::ChargeOfGamma1(1.5),
    ),
    pzt(
        "pzt4_charge_2G1",
        "pzt4 conducting",
        PZT4,
        ElectrodeCase::ChargeOfGamma1(2.0),
    ),
    pzt(
        "pzt4_potential_of_6e-7",
        "pzt4 potential",
        PZT4,
        ElectrodeCase::PotentialOfCharge(6e-7),
    ),
    pzt(
        "pzt4_potential_of_2G1",
        "pzt4 potential",
        PZT4,
        ElectrodeCase::PotentialOfGamma1(2.0),
    ),
    pzt(
        "pzt4_insulating",
        "pzt4 insulating",
        PZT4,
        ElectrodeCase::Insulating,
    ),
    pzt(
        "pzt5h_charge_6e-7",
        "pzt5h conducting",
        PZT5H,
        ElectrodeCase::Charge(6e-7),
    ),
    elastic("aluminium", ALUMINIUM),
    elastic("elastic_nu_0.5", NU_HALF),
];

const fn pzt(
    label: &'static str,
    family: &'static str,
    material: &'static str,
    electrode: ElectrodeCase,
) -> MaterialCase {
    MaterialCase {
        label,
        family,
        material,
        electrode,
        radius: 0.06,
        normal_load: 2000.0,
    }
}

const fn elastic(label: &'static str, material: &'static str) -> MaterialCase {
    MaterialCase {
        label,
        family: label,
        material,
        electrode: ElectrodeCase::None,
        radius: 0.01,
        normal_load: 2240.0,
    }
}

/// Friction coefficients η.
const FRICTIONS: [f64; 6] = [0.05, 0.1, 0.2, 0.3, 0.5, 0.8];
/// Peak |Q| of a history, as a fraction of ηP (not used by the random history).
const AMPLITUDES: [f64; 6] = [0.1, 0.3, 0.5, 0.7, 0.85, 0.95];
/// Load-history kinds.
const KINDS: [Kind; 6] = [
    Kind::Symmetric,
    Kind::Figure3,
    Kind::PartialUnload,
    Kind::NonZeroMean,
    Kind::VariableAmplitude,
    Kind::RandomVariableAmplitude,
];
/// `steps_per_segment`.
const STEPS_PER_SEGMENT: [usize; 3] = [5, 10, 40];
/// `max_step` (fraction of ηP); `None` is the default 0.05 ηP.
const MAX_STEPS: [Option<f64>; 3] = [None, Some(0.01), Some(0.0025)];
/// M.
const COLLOCATION: [usize; 3] = [32, 64, 128];
/// Seeds of the random variable-amplitude history.
const SEEDS: [u64; 3] = [1, 2, 3];
/// Reversals of the random variable-amplitude history.
const RANDOM_REVERSALS: usize = 100;

/// Lead-in `[t, Q]` points, cycle `[Δt, Q]` points and repeats (Q in fractions of ηP).
type HistoryShape = (Vec<(f64, f64)>, Vec<(f64, f64)>, usize);

/// The shape of Q(t).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    /// 0 → A, then three cycles A → −A → A.
    Symmetric,
    /// The paper's Figure 3 scaled to peak A: 0.6A, A, 0.6A, 0, −0.6A, −A (A = 0.5 is the paper's).
    Figure3,
    /// 0.8A, 0.2A, 0.8A, A (after `scenarios/partial_unload_reload.json`).
    PartialUnload,
    /// 0 → A, then three cycles A → 0.2A → A.
    NonZeroMean,
    /// ±A/3 then ±A blocks, three times (after `scenarios/variable_amplitude.json`).
    VariableAmplitude,
    /// 100 reversals, amplitudes uniform in 0.1 … 0.7 ηP, alternating sign, seeded.
    RandomVariableAmplitude,
}

impl Kind {
    fn word(self) -> &'static str {
        match self {
            Kind::Symmetric => "symmetric",
            Kind::Figure3 => "figure3",
            Kind::PartialUnload => "partial_unload",
            Kind::NonZeroMean => "nonzero_mean",
            Kind::VariableAmplitude => "variable_amplitude",
            Kind::RandomVariableAmplitude => "random_va",
        }
    }

    /// Lead-in points, cycle points and repeats, in fractions of ηP.
    fn history(self, a: f64, seed: u64) -> HistoryShape {
        match self {
            Kind::Symmetric => (vec![(0.0, 0.0), (1.0, a)], vec![(2.0, -a), (4.0, a)], 3),
            Kind::Figure3 => (
                vec![
                    (0.0, 0.0),
                    (1.0, 0.6 * a),
                    (2.0, a),
                    (3.0, 0.6 * a),
                    (4.0, 0.0),
                    (5.0, -0.6 * a),
                    (6.0, -a),
                ],
                Vec::new(),
                1,
            ),
            Kind::PartialUnload => (
                vec![
                    (0.0, 0.0),
                    (1.0, 0.8 * a),
                    (2.0, 0.2 * a),
                    (3.0, 0.8 * a),
                    (4.0, a),
                ],
                Vec::new(),
                1,
            ),
            Kind::NonZeroMean => (
                vec![(0.0, 0.0), (1.0, a)],
                vec![(1.0, 0.2 * a), (2.0, a)],
                3,
            ),
            Kind::VariableAmplitude => (
                vec![(0.0, 0.0), (1.0, a / 3.0)],
                vec![(1.0, -a / 3.0), (2.0, a / 3.0), (3.0, -a), (4.0, a)],
                3,
            ),
            Kind::RandomVariableAmplitude => {
                let mut rng = SplitMix(seed);
                let mut points = vec![(0.0, 0.0)];
                for k in 1..=RANDOM_REVERSALS {
                    let amplitude = 0.1 + 0.6 * rng.unit();
                    let sign = if k % 2 == 1 { 1.0 } else { -1.0 };
                    points.push((k as f64, sign * round6(amplitude)));
                }
                (points, Vec::new(), 1)
            }
        }
    }
}

fn round6(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}

/// SplitMix64: a small seeded generator (no dependency).
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// One point of the grid, as indices into the axes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
struct Point {
    material: usize,
    friction: usize,
    amplitude: usize,
    kind: usize,
    steps_per_segment: usize,
    max_step: usize,
    collocation: usize,
    seed: usize,
}

impl Point {
    fn kind(&self) -> Kind {
        KINDS[self.kind]
    }

    /// The run's name: every parameter, readable.
    fn id(&self) -> String {
        let kind = self.kind();
        let amplitude = match kind {
            Kind::RandomVariableAmplitude => format!("seed{}", SEEDS[self.seed]),
            _ => format!("A{}", AMPLITUDES[self.amplitude]),
        };
        format!(
            "{}_eta{}_{}_{}_sps{}_max{}_M{}",
            MATERIALS[self.material].label,
            FRICTIONS[self.friction],
            kind.word(),
            amplitude,
            STEPS_PER_SEGMENT[self.steps_per_segment],
            max_step_word(MAX_STEPS[self.max_step]),
            COLLOCATION[self.collocation],
        )
    }
}

fn max_step_word(m: Option<f64>) -> String {
    m.map_or("default".to_string(), |m| m.to_string())
}

/// Draws grid points with balanced marginals: each axis deals its values from a shuffled bag,
/// refilled when empty, so every value is drawn equally often.
struct Sampler {
    rng: SplitMix,
    bags: Vec<Vec<usize>>,
    sizes: [usize; 8],
}

impl Sampler {
    fn new(seed: u64) -> Self {
        Self {
            rng: SplitMix(seed.wrapping_mul(0x2545_F491_4F6C_DD1D) ^ 0x5DEE_CE66),
            bags: vec![Vec::new(); 8],
            sizes: [
                MATERIALS.len(),
                FRICTIONS.len(),
                AMPLITUDES.len(),
                KINDS.len(),
                STEPS_PER_SEGMENT.len(),
                MAX_STEPS.len(),
                COLLOCATION.len(),
                SEEDS.len(),
            ],
        }
    }

    fn deal(&mut self, axis: usize) -> usize {
        if self.bags[axis].is_empty() {
            let mut bag: Vec<usize> = (0..self.sizes[axis]).collect();
            for i in (1..bag.len()).rev() {
                let j = self.rng.below(i + 1);
                bag.swap(i, j);
            }
            self.bags[axis] = bag;
        }
        self.bags[axis].pop().expect("refilled")
    }

    fn draw(&mut self) -> Point {
        Point {
            material: self.deal(0),
            friction: self.deal(1),
            amplitude: self.deal(2),
            kind: self.deal(3),
            steps_per_segment: self.deal(4),
            max_step: self.deal(5),
            collocation: self.deal(6),
            seed: self.deal(7),
        }
    }
}

/// Constants of the material cases that need a solve: Γ1 and the potentials.
struct Electrics {
    /// Γ1 = kP of PZT-4 at P = 2000 N/m (C/m).
    gamma1: f64,
    /// φ0 of the conducting PZT-4 punch at each charge asked for (C/m → V).
    potentials: Vec<(f64, f64)>,
}

impl Electrics {
    fn measure() -> Self {
        let base = scenario_json(
            "probe",
            &MATERIALS[1],
            &electrode_json(ElectrodeCase::Charge(6e-7)),
            0.3,
            None,
            64,
        );
        let scenario = build(&base).expect("the probe scenario is valid");
        let gamma1 = scenario.model.pressure_charge(scenario.normal_load);
        let mut potentials = Vec::new();
        for charge in [6e-7, 2.0 * gamma1] {
            let text = scenario_json(
                "probe",
                &MATERIALS[1],
                &electrode_json(ElectrodeCase::Charge(charge)),
                0.3,
                None,
                64,
            );
            let scenario = build(&text).expect("the probe scenario is valid");
            let solution = fretsim::solve(&scenario, &mut fretsim::history::NoObserver)
                .expect("normal loading of the probe solves");
            let phi = solution
                .summary
                .normal_loading
                .potential
                .expect("a conducting punch has a potential");
            potentials.push((charge, phi));
        }
        Self { gamma1, potentials }
    }

    fn potential(&self, charge: f64) -> f64 {
        self.potentials
            .iter()
            .find(|(c, _)| (c - charge).abs() <= 1e-12 * charge.abs())
            .map(|p| p.1)
            .expect("a measured potential")
    }

    /// The electrode with numbers, and (charge, charge/Γ1, potential) for the CSV.
    fn resolve(&self, e: ElectrodeCase) -> (ElectrodeCase, Option<f64>, Option<f64>) {
        match e {
            ElectrodeCase::ChargeOfGamma1(f) => (
                ElectrodeCase::Charge(f * self.gamma1),
                Some(f * self.gamma1),
                None,
            ),
            ElectrodeCase::PotentialOfGamma1(f) => {
                let phi = self.potential(f * self.gamma1);
                (ElectrodeCase::Potential(phi), None, Some(phi))
            }
            ElectrodeCase::PotentialOfCharge(c) => {
                let phi = self.potential(c);
                (ElectrodeCase::Potential(phi), None, Some(phi))
            }
            ElectrodeCase::Charge(c) => (e, Some(c), None),
            ElectrodeCase::Potential(phi) => (e, None, Some(phi)),
            ElectrodeCase::None | ElectrodeCase::Insulating => (e, None, None),
        }
    }
}

/// The electrode's JSON, of a resolved case.
fn electrode_json(e: ElectrodeCase) -> String {
    match e {
        ElectrodeCase::None => r#"{ "kind": "none" }"#.to_string(),
        ElectrodeCase::Insulating => r#"{ "kind": "insulating" }"#.to_string(),
        ElectrodeCase::Charge(c) => format!(r#"{{ "kind": "conducting", "charge": {c:e} }}"#),
        ElectrodeCase::Potential(phi) => {
            format!(r#"{{ "kind": "conducting", "potential": {phi:e} }}"#)
        }
        ElectrodeCase::ChargeOfGamma1(_)
        | ElectrodeCase::PotentialOfGamma1(_)
        | ElectrodeCase::PotentialOfCharge(_) => {
            unreachable!("resolved before")
        }
    }
}

/// The scenario file's text.
fn scenario_json(
    name: &str,
    case: &MaterialCase,
    electrode: &str,
    friction: f64,
    history: Option<String>,
    collocation: usize,
) -> String {
    let history = history.map_or(String::new(), |h| {
        format!(",\n  \"tangential_history\": {h}")
    });
    format!(
        "{{\n  \"name\": \"{name}\",\n  \"material\": {},\n  \"punch\": {{ \"radius\": {}, \"electrode\": {electrode} }},\n  \
         \"friction\": {friction},\n  \"normal_load\": {},\n  \"numerics\": {{ \"collocation_points\": {collocation} }},\n  \
         \"output\": {{ \"turning_point_fields\": false, \"field_points\": 16 }}{history}\n}}\n",
        case.material, case.radius, case.normal_load
    )
}

fn points_json(points: &[(f64, f64)]) -> String {
    let items: Vec<String> = points.iter().map(|(t, q)| format!("[{t}, {q}]")).collect();
    format!("[{}]", items.join(", "))
}

/// The history's JSON.
fn history_json(p: &Point) -> String {
    let a = AMPLITUDES[p.amplitude];
    let (points, cycle, repeats) = p.kind().history(a, SEEDS[p.seed]);
    let max_step = MAX_STEPS[p.max_step].map_or(String::new(), |m| format!(", \"max_step\": {m}"));
    let cycle = if cycle.is_empty() {
        String::new()
    } else {
        format!(
            ", \"cycle\": {}, \"repeats\": {repeats}",
            points_json(&cycle)
        )
    };
    format!(
        "{{ \"unit\": \"fraction_of_limit\", \"points\": {}{cycle}, \"steps_per_segment\": {}{max_step} }}",
        points_json(&points),
        STEPS_PER_SEGMENT[p.steps_per_segment]
    )
}

/// Parse and validate as a user's file is.
fn build(text: &str) -> Result<fretsim::Scenario, String> {
    let raw = fretsim::parse(text, Path::new("<failure map>")).map_err(|e| e.to_string())?;
    fretsim::validate(raw).map_err(|issues| {
        issues
            .iter()
            .map(|i| i.to_string())
            .collect::<Vec<_>>()
            .join("; ")
    })
}

/// A scenario with its solver set.
fn with_solver(text: &str, solver: &str) -> String {
    text.replace(
        "\"numerics\": {",
        &format!("\"numerics\": {{ \"solver\": \"{solver}\","),
    )
}

/// The short form of a failure: its kind and what failed, without numbers.
fn short_failure(f: &SolveFailure) -> String {
    match f {
        SolveFailure::NoConvergence { what, .. } => format!("no convergence: {what}"),
        SolveFailure::NonFinite { field } => format!("non-finite: {field}"),
        SolveFailure::Inadmissible { check, .. } => format!("inadmissible: {check}"),
        SolveFailure::NoAdmissibleState { reason } => {
            format!("no admissible state: {}", without_numbers(reason))
        }
        SolveFailure::NeitherSolver { general, .. } => {
            format!("neither solver; general: {}", short_failure(general))
        }
    }
}

/// Text up to its first parenthesis, numbers replaced by `#`.
fn without_numbers(text: &str) -> String {
    let head = text.split(" (").next().unwrap_or(text);
    let mut out = String::new();
    let mut in_number = false;
    for c in head.chars() {
        let numeric = c.is_ascii_digit()
            || (in_number && matches!(c, '.' | 'e' | 'E' | '-' | '+'))
            || (c == '−' && in_number);
        if numeric {
            if !in_number {
                out.push('#');
            }
            in_number = true;
        } else {
            in_number = false;
            out.push(c);
        }
    }
    out.trim().to_string()
}

/// The deadline marker carried by the panic that abandons a run.
struct Deadline;

/// Counts the steps and the handovers of a run and abandons it at its deadline.
struct Counter {
    deadline: Instant,
    last: Instant,
    steps: usize,
    general_steps: usize,
    general_seconds: f64,
    most_stick_zones: usize,
    handovers: Vec<String>,
}

impl Counter {
    fn new(cap: Duration) -> Self {
        let now = Instant::now();
        Self {
            deadline: now + cap,
            last: now,
            steps: 0,
            general_steps: 0,
            general_seconds: 0.0,
            most_stick_zones: 0,
            handovers: Vec::new(),
        }
    }
}

impl Observer for Counter {
    fn on_step(&mut self, record: &StepRecord, _state: StateView<'_>) {
        let now = Instant::now();
        if record.step > 0 {
            self.steps += 1;
            if record.solver == SolverKind::General {
                self.general_steps += 1;
                self.general_seconds += (now - self.last).as_secs_f64();
            }
            self.most_stick_zones = self.most_stick_zones.max(record.zones.stick);
        }
        self.last = now;
        if now > self.deadline {
            std::panic::panic_any(Deadline);
        }
    }

    fn on_handover(&mut self, failure: &StepFailure) {
        self.handovers.push(short_failure(&failure.failure));
    }
}

/// How a run ended.
#[derive(Debug, Clone, Default)]
struct Outcome {
    status: &'static str,
    failure_short: String,
    failure: String,
    steps: usize,
    general_steps: usize,
    general_seconds: f64,
    most_stick_zones: usize,
    handovers: Vec<String>,
    stalled: usize,
    seconds: f64,
}

/// Solve on a child thread under a cap; a step that never returns is waited for `grace` more.
fn run_capped(scenario: fretsim::Scenario, cap: Duration, grace: Duration) -> Outcome {
    let (send, receive) = mpsc::channel();
    let start = Instant::now();
    let worker = std::thread::Builder::new()
        .name("failure-map-run".into())
        .stack_size(64 << 20)
        .spawn(move || {
            let mut counter = Counter::new(cap);
            let result = catch_unwind(AssertUnwindSafe(|| fretsim::solve(&scenario, &mut counter)));
            let mut o = Outcome {
                steps: counter.steps,
                general_steps: counter.general_steps,
                general_seconds: counter.general_seconds,
                most_stick_zones: counter.most_stick_zones,
                handovers: counter.handovers,
                ..Outcome::default()
            };
            match result {
                Ok(Ok(solution)) => {
                    o.stalled = solution
                        .summary
                        .warnings
                        .iter()
                        .find(|w| w.contains("stalled residual"))
                        .and_then(|w| w.split(' ').next()?.parse().ok())
                        .unwrap_or(0);
                    match solution.failure {
                        None => o.status = "completed",
                        Some(e) => {
                            o.status = "failed";
                            o.failure_short = match &e {
                                fretsim::Error::Solve { failure, .. } => short_failure(failure),
                                other => without_numbers(&other.to_string()),
                            };
                            o.failure = e.to_string();
                        }
                    }
                }
                Ok(Err(e)) => {
                    o.status = "normal_failed";
                    o.failure_short = match &e {
                        fretsim::Error::Solve { failure, .. } => short_failure(failure),
                        other => without_numbers(&other.to_string()),
                    };
                    o.failure = e.to_string();
                }
                Err(payload) if payload.is::<Deadline>() => {
                    o.status = "timeout";
                    o.failure_short = "timeout".into();
                    o.failure = format!("abandoned after {} s", cap.as_secs());
                }
                Err(payload) => {
                    o.status = "panic";
                    let message = payload
                        .downcast_ref::<String>()
                        .cloned()
                        .or_else(|| payload.downcast_ref::<&str>().map(|s| s.to_string()))
                        .unwrap_or_default();
                    o.failure_short = format!("panic: {}", without_numbers(&message));
                    o.failure = format!("panic: {message}");
                }
            }
            // The receiver may have given up; nothing to do then.
            let _ = send.send(o);
        })
        .expect("spawn a run thread");
    match receive.recv_timeout(cap + grace) {
        Ok(mut o) => {
            o.seconds = start.elapsed().as_secs_f64();
            let _ = worker.join();
            o
        }
        Err(_) => Outcome {
            status: "hung",
            failure_short: "hung".into(),
            failure: format!("no step returned within {} s", (cap + grace).as_secs()),
            seconds: start.elapsed().as_secs_f64(),
            ..Outcome::default()
        },
    }
}

/// The handover reasons, deduplicated, with their counts: `reason ×n; …`.
fn reasons(handovers: &[String]) -> String {
    let mut counts: BTreeMap<&str, usize> = BTreeMap::new();
    for h in handovers {
        *counts.entry(h.as_str()).or_default() += 1;
    }
    counts
        .iter()
        .map(|(r, n)| format!("{r} x{n}"))
        .collect::<Vec<_>>()
        .join("; ")
}

/// One row of `results.csv`.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct Row {
    id: String,
    batch: String,
    material: String,
    family: String,
    charge_c_per_m: Option<f64>,
    charge_over_gamma1: Option<f64>,
    potential_v: Option<f64>,
    friction: f64,
    kind: String,
    amplitude: String,
    steps_per_segment: usize,
    max_step: String,
    collocation_points: usize,
    planned_steps: usize,
    auto_status: String,
    auto_failure_short: String,
    auto_failure: String,
    auto_steps: usize,
    general_steps: usize,
    handovers: usize,
    handover_reasons: String,
    most_stick_zones: usize,
    stalled_steps: usize,
    auto_seconds: f64,
    general_seconds: f64,
    spectral_status: String,
    spectral_failure_short: String,
    spectral_steps: usize,
    spectral_seconds: f64,
}

/// One row of `rejected.csv`.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct Rejected {
    id: String,
    batch: String,
    issues: String,
}

struct Options {
    out: PathBuf,
    runs: usize,
    seed: u64,
    budget: Duration,
    cap: Duration,
    spectral_cap: Duration,
    random_share: f64,
    fine_share: f64,
    summarise_only: bool,
    dry_run: bool,
    /// Run only the drawn points whose ids this file lists (one a line).
    only: Option<PathBuf>,
}

fn usage() -> ! {
    eprintln!(
        "usage: failure_map OUT_DIR [--runs N] [--seed S] [--budget-min MIN] [--cap-s S] \
         [--spectral-cap-s S] [--random-share F] [--fine-share F] [--only IDS_FILE] [--dry-run] \
         [--summarise]"
    );
    std::process::exit(2)
}

fn parse_options() -> Options {
    let mut args = std::env::args().skip(1);
    let mut o = Options {
        out: PathBuf::new(),
        runs: 200,
        seed: 1,
        budget: Duration::from_secs(70 * 60),
        cap: Duration::from_secs(120),
        spectral_cap: Duration::from_secs(30),
        random_share: 0.05,
        fine_share: 0.15,
        summarise_only: false,
        dry_run: false,
        only: None,
    };
    let mut out = None;
    while let Some(a) = args.next() {
        let mut value = |name: &str| -> f64 {
            args.next().and_then(|v| v.parse().ok()).unwrap_or_else(|| {
                eprintln!("{name} needs a number");
                usage()
            })
        };
        match a.as_str() {
            "--runs" => o.runs = value("--runs") as usize,
            "--seed" => o.seed = value("--seed") as u64,
            "--budget-min" => o.budget = Duration::from_secs_f64(60.0 * value("--budget-min")),
            "--cap-s" => o.cap = Duration::from_secs_f64(value("--cap-s")),
            "--spectral-cap-s" => {
                o.spectral_cap = Duration::from_secs_f64(value("--spectral-cap-s"))
            }
            "--random-share" => o.random_share = value("--random-share"),
            "--fine-share" => o.fine_share = value("--fine-share"),
            "--summarise" => o.summarise_only = true,
            "--dry-run" => o.dry_run = true,
            "--only" => o.only = Some(args.next().map(PathBuf::from).unwrap_or_else(|| usage())),
            s if !s.starts_with('-') && out.is_none() => out = Some(PathBuf::from(s)),
            _ => usage(),
        }
    }
    o.out = out.unwrap_or_else(|| usage());
    o
}

/// The draw: `runs` distinct points, the random-history and the 40-steps-per-segment shares
/// capped in every prefix (an over-share draw is dealt again on that axis).
fn draw(o: &Options) -> Vec<Point> {
    let mut sampler = Sampler::new(o.seed);
    let random = KINDS
        .iter()
        .position(|k| *k == Kind::RandomVariableAmplitude)
        .expect("a random kind");
    let fine = STEPS_PER_SEGMENT
        .iter()
        .position(|s| *s == 40)
        .expect("40 steps per segment");
    let mut seen = BTreeSet::new();
    let mut points = Vec::new();
    let (mut n_random, mut n_fine) = (0usize, 0usize);
    let mut attempts = 0;
    while points.len() < o.runs && attempts < 100 * o.runs {
        attempts += 1;
        let mut p = sampler.draw();
        // The share is kept in every prefix of the draw, since a budget may end it early.
        let drawn = points.len() + 1;
        let allowed = |n: usize, share: f64| (n as f64) < share * drawn as f64;
        while p.kind == random && !allowed(n_random, o.random_share) {
            p.kind = sampler.deal(3);
        }
        while p.steps_per_segment == fine && !allowed(n_fine, o.fine_share) {
            p.steps_per_segment = sampler.deal(4);
        }
        // The random history has no amplitude axis (and the others no seed): one key each.
        // Its 100 reversals at the finer step limits are tens of thousands of steps: it runs
        // at the default limit (0.05 ηP) only.
        if p.kind == random {
            p.amplitude = 0;
            p.max_step = 0;
        } else {
            p.seed = 0;
        }
        if !seen.insert(p) {
            continue;
        }
        n_random += usize::from(p.kind == random);
        n_fine += usize::from(p.steps_per_segment == fine);
        points.push(p);
    }
    points
}

fn read_rows<T: for<'de> Deserialize<'de>>(path: &Path) -> Vec<T> {
    let Ok(mut reader) = csv::Reader::from_path(path) else {
        return Vec::new();
    };
    reader.deserialize().filter_map(Result::ok).collect()
}

fn appender(path: &Path) -> csv::Writer<fs::File> {
    let exists = path.exists();
    let file = fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
        .unwrap_or_else(|e| panic!("cannot open {}: {e}", path.display()));
    csv::WriterBuilder::new()
        .has_headers(!exists)
        .from_writer(file)
}

fn main() {
    let o = parse_options();
    fs::create_dir_all(&o.out).unwrap_or_else(|e| panic!("cannot create {}: {e}", o.out.display()));
    let results = o.out.join("results.csv");
    let rejected_path = o.out.join("rejected.csv");
    if o.summarise_only {
        summarise(&o.out);
        return;
    }
    // Silence the panic that abandons a run at its deadline; report any other.
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        if !info.payload().is::<Deadline>() {
            default_hook(info);
        }
    }));
    let electrics = Electrics::measure();
    eprintln!(
        "PZT-4 at P = 2000 N/m: Γ1 = kP = {:.4e} C/m; φ0 at Γ = 6e-7: {:.4e} V, at 2Γ1: {:.4e} V",
        electrics.gamma1, electrics.potentials[0].1, electrics.potentials[1].1
    );
    let done: BTreeSet<String> = read_rows::<Row>(&results)
        .into_iter()
        .map(|r| r.id)
        .chain(
            read_rows::<Rejected>(&rejected_path)
                .into_iter()
                .map(|r| r.id),
        )
        .collect();
    let points = draw(&o);
    let only: Option<BTreeSet<String>> = o.only.as_ref().map(|path| {
        fs::read_to_string(path)
            .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
            .lines()
            .map(|l| l.trim().to_string())
            .filter(|l| !l.is_empty())
            .collect()
    });
    let todo: Vec<&Point> = points
        .iter()
        .filter(|p| !done.contains(&p.id()))
        .filter(|p| only.as_ref().is_none_or(|ids| ids.contains(&p.id())))
        .collect();
    eprintln!(
        "{} points drawn (seed {}), {} already in {}, {} to run",
        points.len(),
        o.seed,
        points.len() - todo.len(),
        results.display(),
        todo.len()
    );
    if o.dry_run {
        for p in &todo {
            println!("{}", p.id());
        }
        return;
    }
    let batch = format!("seed{}", o.seed);
    let mut rows = appender(&results);
    let mut rejected = appender(&rejected_path);
    let start = Instant::now();
    for (i, p) in todo.iter().enumerate() {
        if start.elapsed() > o.budget {
            eprintln!("budget reached after {i} runs; {} not run", todo.len() - i);
            break;
        }
        let id = p.id();
        let case = &MATERIALS[p.material];
        let (electrode, charge, potential) = electrics.resolve(case.electrode);
        let text = scenario_json(
            &id,
            case,
            &electrode_json(electrode),
            FRICTIONS[p.friction],
            Some(history_json(p)),
            COLLOCATION[p.collocation],
        );
        let scenario = match build(&text) {
            Ok(s) => s,
            Err(issues) => {
                eprintln!("[{i}] {id}: rejected: {issues}");
                rejected
                    .serialize(Rejected {
                        id,
                        batch: batch.clone(),
                        issues,
                    })
                    .expect("write rejected.csv");
                rejected.flush().expect("flush rejected.csv");
                continue;
            }
        };
        let planned = scenario.history.as_ref().map_or(0, |h| h.steps().len());
        let auto = run_capped(scenario, o.cap, Duration::from_secs(600));
        let spectral = build(&with_solver(&text, "spectral"))
            .map(|s| run_capped(s, o.spectral_cap, Duration::from_secs(600)))
            .expect("the same scenario with solver = spectral is valid");
        let kind = p.kind();
        let row = Row {
            id: id.clone(),
            batch: batch.clone(),
            material: case.label.into(),
            family: case.family.into(),
            charge_c_per_m: charge,
            charge_over_gamma1: charge.map(|c| round6(c / electrics.gamma1)),
            potential_v: potential,
            friction: FRICTIONS[p.friction],
            kind: kind.word().into(),
            amplitude: match kind {
                Kind::RandomVariableAmplitude => format!("0.1-0.7 seed {}", SEEDS[p.seed]),
                _ => AMPLITUDES[p.amplitude].to_string(),
            },
            steps_per_segment: STEPS_PER_SEGMENT[p.steps_per_segment],
            max_step: max_step_word(MAX_STEPS[p.max_step]),
            collocation_points: COLLOCATION[p.collocation],
            planned_steps: planned,
            auto_status: auto.status.into(),
            auto_failure_short: auto.failure_short.clone(),
            auto_failure: auto.failure.clone(),
            auto_steps: auto.steps,
            general_steps: auto.general_steps,
            handovers: auto.handovers.len(),
            handover_reasons: reasons(&auto.handovers),
            most_stick_zones: auto.most_stick_zones,
            stalled_steps: auto.stalled,
            auto_seconds: round6(auto.seconds),
            general_seconds: round6(auto.general_seconds),
            spectral_status: spectral.status.into(),
            spectral_failure_short: spectral.failure_short.clone(),
            spectral_steps: spectral.steps,
            spectral_seconds: round6(spectral.seconds),
        };
        eprintln!(
            "[{i}/{}] {id}: auto {} {}/{} steps ({} general, {} handovers) {:.1} s; spectral {} {:.1} s{}",
            todo.len(),
            auto.status,
            auto.steps,
            planned,
            auto.general_steps,
            auto.handovers.len(),
            auto.seconds,
            spectral.status,
            spectral.seconds,
            if auto.failure.is_empty() {
                String::new()
            } else {
                format!(" — {}", auto.failure)
            }
        );
        rows.serialize(row).expect("write results.csv");
        rows.flush().expect("flush results.csv");
        if auto.status == "hung" || spectral.status == "hung" {
            eprintln!("a run did not return; stopping (rerun to resume)");
            std::process::exit(1);
        }
    }
    drop(rows);
    summarise(&o.out);
}

/// Completed and total, by a key.
#[derive(Default)]
struct Tally {
    runs: usize,
    auto_done: usize,
    spectral_done: usize,
    taken_over: usize,
    seconds: f64,
}

fn percent(n: usize, d: usize) -> String {
    if d == 0 {
        "–".into()
    } else {
        format!("{:.1} %", 100.0 * n as f64 / d as f64)
    }
}

fn table(out: &mut String, title: &str, rows: &[Row], key: impl Fn(&Row) -> String) {
    let mut tallies: BTreeMap<String, Tally> = BTreeMap::new();
    for r in rows {
        let t = tallies.entry(key(r)).or_default();
        t.runs += 1;
        t.auto_done += usize::from(r.auto_status == "completed");
        t.spectral_done += usize::from(r.spectral_status == "completed");
        t.taken_over += usize::from(r.general_steps > 0);
        t.seconds += r.auto_seconds;
    }
    let _ = writeln!(
        out,
        "\n| {title} | runs | auto completes | spectral alone completes | general solver took steps | mean auto time (s) |\n|---|---|---|---|---|---|"
    );
    for (k, t) in &tallies {
        let _ = writeln!(
            out,
            "| {k} | {} | {} ({}) | {} ({}) | {} | {:.2} |",
            t.runs,
            t.auto_done,
            percent(t.auto_done, t.runs),
            t.spectral_done,
            percent(t.spectral_done, t.runs),
            t.taken_over,
            t.seconds / t.runs as f64
        );
    }
}

/// Text for a Markdown table cell (`|q|` would end the cell).
fn cell(text: &str) -> String {
    text.replace('|', "\\|")
}

/// `summary.md` from `results.csv` and `rejected.csv`.
fn summarise(dir: &Path) {
    let rows: Vec<Row> = read_rows(&dir.join("results.csv"));
    let rejected: Vec<Rejected> = read_rows(&dir.join("rejected.csv"));
    let mut out = String::new();
    let total_seconds: f64 = rows
        .iter()
        .map(|r| r.auto_seconds + r.spectral_seconds)
        .sum();
    let _ = writeln!(
        out,
        "# Failure map\n\n{} valid runs ({} rejected by the validator), {:.0} s of solving.",
        rows.len(),
        rejected.len(),
        total_seconds
    );
    table(&mut out, "all", &rows, |_| "all".into());
    table(&mut out, "auto status", &rows, |r| r.auto_status.clone());
    table(&mut out, "material", &rows, |r| r.material.clone());
    table(&mut out, "family", &rows, |r| r.family.clone());
    table(&mut out, "η", &rows, |r| format!("{:.2}", r.friction));
    table(&mut out, "history", &rows, |r| r.kind.clone());
    table(&mut out, "amplitude (ηP)", &rows, |r| {
        if r.kind == "random_va" {
            "0.1-0.7 (random)".into()
        } else {
            r.amplitude.clone()
        }
    });
    table(&mut out, "steps per segment", &rows, |r| {
        format!("{:>2}", r.steps_per_segment)
    });
    table(&mut out, "max_step (ηP)", &rows, |r| r.max_step.clone());
    table(&mut out, "M", &rows, |r| {
        format!("{:>3}", r.collocation_points)
    });
    table(&mut out, "family × η", &rows, |r| {
        format!("{} η={:.2}", r.family, r.friction)
    });
    // Failures of auto, grouped by their short message.
    let mut failures: BTreeMap<String, Vec<&Row>> = BTreeMap::new();
    for r in rows.iter().filter(|r| r.auto_status != "completed") {
        failures
            .entry(format!("{}: {}", r.auto_status, r.auto_failure_short))
            .or_default()
            .push(r);
    }
    let _ = writeln!(
        out,
        "\n## Runs that auto did not complete\n\n| status: failure | runs | example (id: message) |\n|---|---|---|"
    );
    for (k, list) in &failures {
        let _ = writeln!(
            out,
            "| {} | {} | `{}`: {} |",
            cell(k),
            list.len(),
            list[0].id,
            cell(&list[0].auto_failure)
        );
    }
    // Spectral-only failures, by message.
    let mut spectral: BTreeMap<String, usize> = BTreeMap::new();
    for r in rows.iter().filter(|r| r.spectral_status != "completed") {
        *spectral
            .entry(format!(
                "{}: {}",
                r.spectral_status, r.spectral_failure_short
            ))
            .or_default() += 1;
    }
    let _ = writeln!(
        out,
        "\n## Runs the spectral solver alone did not complete\n\n| status: failure | runs |\n|---|---|"
    );
    for (k, n) in &spectral {
        let _ = writeln!(out, "| {} | {n} |", cell(k));
    }
    // Takeovers.
    let taken: Vec<&Row> = rows.iter().filter(|r| r.general_steps > 0).collect();
    let steps: usize = taken.iter().map(|r| r.general_steps).sum();
    let handovers: usize = taken.iter().map(|r| r.handovers).sum();
    let general_seconds: f64 = taken.iter().map(|r| r.general_seconds).sum();
    let _ = writeln!(
        out,
        "\n## General-solver takeovers\n\n{} runs, {} handovers, {} general steps ({:.2} per handover), {:.0} s in general steps ({:.3} s per step); \
         {} of these runs completed.",
        taken.len(),
        handovers,
        steps,
        steps as f64 / handovers.max(1) as f64,
        general_seconds,
        general_seconds / steps.max(1) as f64,
        taken
            .iter()
            .filter(|r| r.auto_status == "completed")
            .count()
    );
    let mut why: BTreeMap<String, (usize, BTreeSet<String>)> = BTreeMap::new();
    for r in &taken {
        for part in r.handover_reasons.split("; ").filter(|s| !s.is_empty()) {
            let (reason, n) = part.rsplit_once(" x").unwrap_or((part, "1"));
            let e = why.entry(reason.to_string()).or_default();
            e.0 += n.parse::<usize>().unwrap_or(1);
            e.1.insert(r.id.clone());
        }
    }
    let _ = writeln!(
        out,
        "\n| handover reason | handovers | runs |\n|---|---|---|"
    );
    for (reason, (n, ids)) in &why {
        let _ = writeln!(out, "| {} | {n} | {} |", cell(reason), ids.len());
    }
    let mut steps_hist: BTreeMap<usize, usize> = BTreeMap::new();
    for r in &taken {
        let bucket = match r.general_steps {
            0..=1 => 1,
            2..=3 => 3,
            4..=10 => 10,
            11..=30 => 30,
            31..=100 => 100,
            101..=1000 => 1000,
            1001..=10_000 => 10_000,
            _ => 100_000,
        };
        *steps_hist.entry(bucket).or_default() += 1;
    }
    let timeouts: Vec<&Row> = rows.iter().filter(|r| r.auto_status == "timeout").collect();
    if !timeouts.is_empty() {
        let progress: f64 = timeouts
            .iter()
            .map(|r| r.auto_steps as f64 / r.planned_steps.max(1) as f64)
            .sum::<f64>()
            / timeouts.len() as f64;
        let _ = writeln!(
            out,
            "\nTimeouts: {} runs, on average {:.1} % of their steps done; {} of them with the general solver holding the step, \
             which took {} steps in them ({:.3} s per step).",
            timeouts.len(),
            100.0 * progress,
            timeouts.iter().filter(|r| r.general_steps > 0).count(),
            timeouts.iter().map(|r| r.general_steps).sum::<usize>(),
            timeouts.iter().map(|r| r.general_seconds).sum::<f64>()
                / timeouts
                    .iter()
                    .map(|r| r.general_steps)
                    .sum::<usize>()
                    .max(1) as f64
        );
    }
    let _ = writeln!(out, "\n| general steps in the run (≤) | runs |\n|---|---|");
    for (b, n) in &steps_hist {
        let _ = writeln!(out, "| {b} | {n} |");
    }
    if !rejected.is_empty() {
        let _ = writeln!(
            out,
            "\n## Rejected by the validator\n\n| id | issues |\n|---|---|"
        );
        for r in &rejected {
            let _ = writeln!(out, "| `{}` | {} |", r.id, cell(&r.issues));
        }
    }
    let path = dir.join("summary.md");
    fs::write(&path, &out).unwrap_or_else(|e| panic!("cannot write {}: {e}", path.display()));
    print!("{out}");
}
