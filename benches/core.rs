//! Criterion benches of the numerical core, parameterised by the number of collocation nodes M.
//! Run with `cargo bench` (not run in CI). No file I/O, no progress bars.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use fretsim::contact::normal::{NormalOptions, solve_normal};
use fretsim::contact::pressure::Discretisation;
use fretsim::contact::tangential::SlipOptions;
use fretsim::history::{
    DriverState, HistoryState, LoadHistory, LoadPoint, NoObserver, NormalEnd, RunOptions,
    StepRecord, advance, continue_run, run_history, solve_step,
};
use fretsim::scenario::{Scenario, default_scenario};

/// The command's allocator (`src/main.rs`), so that the benches time what a run does.
#[cfg(feature = "mimalloc")]
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

const SIZES: [usize; 5] = [32, 64, 128, 256, 512];

fn kernels(c: &mut Criterion) {
    let mut g = c.benchmark_group("kernel/assemble_and_factor");
    for m in SIZES {
        g.bench_with_input(BenchmarkId::from_parameter(m), &m, |b, &m| {
            b.iter(|| black_box(Discretisation::new(m)))
        });
    }
    g.finish();
}

fn normal(c: &mut Criterion) {
    let sc = default_scenario();
    let mut g = c.benchmark_group("solve/normal_loading");
    g.sample_size(10);
    for m in SIZES {
        let disc = Discretisation::new(m);
        g.bench_with_input(BenchmarkId::from_parameter(m), &m, |b, _| {
            b.iter(|| {
                black_box(
                    solve_normal(&sc.model, &disc, sc.normal_load, NormalOptions::default())
                        .unwrap(),
                )
            })
        });
    }
    g.finish();
}

/// The driver after normal loading and the given load steps (fractions of ηP).
fn driver_after(sc: &Scenario, disc: &Discretisation, loads: &[f64]) -> DriverState {
    let normal = solve_normal(&sc.model, disc, sc.normal_load, NormalOptions::default()).unwrap();
    let mut driver = DriverState::after_normal_loading(&normal);
    for (i, f) in loads.iter().enumerate() {
        step(sc, disc, &mut driver, i + 1, *f);
    }
    driver
}

/// One load step to `f` ηP.
fn step(
    sc: &Scenario,
    disc: &Discretisation,
    driver: &mut DriverState,
    n: usize,
    f: f64,
) -> StepRecord {
    let point = LoadPoint {
        step: n,
        t: n as f64,
        q: f * sc.model.friction * sc.normal_load,
        punch: None,
    };
    advance(
        &sc.model,
        disc,
        driver,
        point,
        SlipOptions::default(),
        &mut NoObserver,
    )
    .unwrap()
}

/// Time one step to `next` ηP from the state after `loads`.
fn bench_step(c: &mut Criterion, name: &str, sizes: &[usize], loads: &[f64], next: f64) {
    let sc = default_scenario();
    let mut g = c.benchmark_group(name);
    g.sample_size(10);
    for &m in sizes {
        let disc = Discretisation::new(m);
        let driver = driver_after(&sc, &disc, loads);
        g.bench_with_input(BenchmarkId::from_parameter(m), &m, |b, _| {
            b.iter(|| black_box(step(&sc, &disc, &mut driver.clone(), loads.len() + 1, next)))
        });
    }
    g.finish();
}

/// Time the state of one step to `next` ηP from the state after `loads`, without the
/// increments (δ, dissipation, δn), which `run_history` computes on a second thread while it
/// solves the next step.
fn bench_state(
    c: &mut Criterion,
    name: &str,
    sizes: &[usize],
    loads: &[f64],
    next: f64,
    options: SlipOptions,
) {
    let sc = default_scenario();
    let mut g = c.benchmark_group(name);
    g.sample_size(10);
    for &m in sizes {
        let disc = Discretisation::new(m);
        let driver = driver_after(&sc, &disc, loads);
        let n = loads.len() + 1;
        let point = LoadPoint {
            step: n,
            t: n as f64,
            q: next * sc.model.friction * sc.normal_load,
            punch: None,
        };
        g.bench_with_input(BenchmarkId::from_parameter(m), &m, |b, _| {
            b.iter(|| {
                let mut d = driver.clone();
                black_box(solve_step(&sc.model, &disc, &mut d, point, options).is_ok())
            })
        });
    }
    g.finish();
}

/// The default history's first loading up to 0.30 ηP (steps of 0.05 ηP): the state from which
/// the forward-step benches take the default run's step to 0.35 ηP. The lead-in takes the
/// default run's own steps, so that the quadratic predictor starts the timed step as it does in
/// a run.
fn lead_in() -> Vec<f64> {
    default_loads(0)[..6].to_vec()
}

fn steps(c: &mut Criterion) {
    // In the middle of the first forward phase.
    let loads = lead_in();
    bench_step(c, "solve/forward_step", &SIZES, &loads, 0.35);
    let options = SlipOptions::default();
    bench_state(
        c,
        "solve/forward_step_state_only",
        &SIZES,
        &loads,
        0.35,
        options,
    );
    // The same without the coarse grid's Jacobian (`Accelerations::coarse_jacobian`), on the
    // grids that have one: the comparison under the same host load.
    let mut carried = options;
    carried.accelerations.coarse_jacobian = false;
    let sizes = [128, 256, 512];
    bench_state(
        c,
        "solve/forward_step_state_carried_jacobian",
        &sizes,
        &loads,
        0.35,
        carried,
    );
}

/// Time per step of four forward steps (0.30 → 0.35 → … → 0.50 ηP, from a clone of the driver
/// after the default history's first loading to 0.30 ηP, [`lead_in`]) as a run takes them ([`continue_run`]: each step's increments
/// on a second thread while the next step is solved), and the same four steps one after the
/// other on one thread ([`advance`]).
fn steps_in_a_run(c: &mut Criterion) {
    let sc = default_scenario();
    let loads = lead_in();
    let next = [0.35, 0.40, 0.45, 0.50];
    let points: Vec<LoadPoint> = next
        .iter()
        .enumerate()
        .map(|(k, f)| LoadPoint {
            step: loads.len() + k + 1,
            t: (loads.len() + k + 1) as f64,
            q: f * sc.model.friction * sc.normal_load,
            punch: None,
        })
        .collect();
    for (name, pipelined) in [
        ("run/forward_step_in_a_run", true),
        ("run/forward_step_sequential", false),
    ] {
        let mut g = c.benchmark_group(name);
        g.sample_size(10);
        for m in SIZES {
            let disc = Discretisation::new(m);
            let driver = driver_after(&sc, &disc, &loads);
            g.bench_with_input(BenchmarkId::from_parameter(m), &m, |b, _| {
                b.iter_custom(|iters| {
                    per_step(iters, next.len(), || {
                        let mut d = driver.clone();
                        if pipelined {
                            let mut records = Vec::new();
                            let mut state = HistoryState::new(d);
                            let failure = continue_run(
                                &sc.model,
                                &disc,
                                &mut state,
                                &points,
                                RunOptions::default(),
                                &mut NoObserver,
                                &mut records,
                            );
                            assert!(failure.is_none());
                            black_box(records);
                        } else {
                            for (k, f) in next.iter().enumerate() {
                                black_box(step(&sc, &disc, &mut d, loads.len() + k + 1, *f));
                            }
                        }
                    })
                })
            });
        }
        g.finish();
    }
}

/// The time of `iters` calls of `steps`, per step (`count` steps a call).
fn per_step(iters: u64, count: usize, mut steps: impl FnMut()) -> std::time::Duration {
    let start = std::time::Instant::now();
    for _ in 0..iters {
        steps();
    }
    start.elapsed() / count as u32
}

fn recalled(c: &mut Criterion) {
    // The same step, 0.30 → 0.35 ηP, in the third forward phase of the default history: that
    // phase began from the same turning state (−½ ηP) as the second, whose step at 0.35 ηP
    // it recalls (`Accelerations::recall`).
    let mut loads = default_loads(1);
    loads.extend((1..=20).map(|i| 0.5 - 0.05 * i as f64));
    loads.extend((1..=16).map(|i| -0.5 + 0.05 * i as f64));
    bench_step(c, "solve/recalled_forward_step", &SIZES, &loads, 0.35);
    bench_state(
        c,
        "solve/recalled_forward_step_state_only",
        &SIZES,
        &loads,
        0.35,
        SlipOptions::default(),
    );
}

fn reversal(c: &mut Criterion) {
    // The first step after the turning point at +½ηP.
    bench_step(c, "solve/reversal_step", &SIZES, &default_loads(0), 0.45);
    // The first step after the next turning point, at −½ηP: it begins in the mixed slip
    // pattern that began the phase before, whose attempt starts from that phase's edge
    // (`Accelerations::mixed_start_guesses`).
    let mut loads = default_loads(0);
    loads.extend((1..=20).map(|i| 0.5 - 0.05 * i as f64));
    bench_step(c, "solve/later_reversal_step", &SIZES, &loads, -0.45);
}

fn cycle(c: &mut Criterion) {
    let sc = default_scenario();
    let lim = sc.model.friction * sc.normal_load;
    let mut g = c.benchmark_group("cycle/normal_plus_one_cycle");
    g.sample_size(10);
    for m in [32, 64] {
        let disc = Discretisation::new(m);
        let normal = NormalEnd::Spectral(Box::new(
            solve_normal(&sc.model, &disc, sc.normal_load, NormalOptions::default()).unwrap(),
        ));
        let history = LoadHistory {
            points: vec![
                (0.0, 0.0),
                (1.0, 0.5 * lim),
                (3.0, -0.5 * lim),
                (5.0, 0.5 * lim),
            ],
            punch: None,
            steps_per_segment: 10,
            max_step: 0.05 * lim,
            control: fretsim::history::Control::Load,
            max_displacement_step: f64::INFINITY,
        };
        g.bench_with_input(BenchmarkId::from_parameter(m), &m, |b, _| {
            b.iter(|| {
                black_box(run_history(
                    &sc.model,
                    &disc,
                    &normal,
                    &history,
                    RunOptions::default(),
                    &mut NoObserver,
                ))
            })
        });
    }
    g.finish();
}

/// The load steps (fractions of ηP) of the default history: 0 → ½, then ±½ cycles, in steps of
/// 0.05.
fn default_loads(cycles: usize) -> Vec<f64> {
    let mut loads: Vec<f64> = (1..=10).map(|i| 0.05 * i as f64).collect();
    for _ in 0..cycles {
        loads.extend((1..=20).map(|i| 0.5 - 0.05 * i as f64));
        loads.extend((1..=20).map(|i| -0.5 + 0.05 * i as f64));
    }
    loads
}

/// Time the default history's cycle after `cycles` cycles (40 steps, +½ → −½ → +½ ηP, from a
/// clone of the driver after the lead-in and those cycles), with δ and the dissipation,
/// sequential `advance`.
fn bench_cycle(c: &mut Criterion, name: &str, cycles: usize) {
    let sc = default_scenario();
    let mut g = c.benchmark_group(name);
    g.sample_size(10);
    for m in SIZES {
        let disc = Discretisation::new(m);
        let before = default_loads(cycles);
        let driver = driver_after(&sc, &disc, &before);
        let cycle = &default_loads(cycles + 1)[before.len()..];
        g.bench_with_input(BenchmarkId::from_parameter(m), &m, |b, _| {
            b.iter(|| {
                let mut d = driver.clone();
                for (k, f) in cycle.iter().enumerate() {
                    black_box(step(&sc, &disc, &mut d, before.len() + k + 1, *f));
                }
            })
        });
    }
    g.finish();
}

fn steady_cycle(c: &mut Criterion) {
    // The second cycle: its forward phase recalls the first cycle's.
    bench_cycle(c, "cycle/steady_cycle", 1);
    // The third cycle, whose phases each begin from the turning state that began the same
    // phase of the second cycle: every step is recalled, with its checks and increments.
    bench_cycle(c, "cycle/repeated_cycle", 2);
}

/// The general element solver on a contact loaded normally with P and the electric load rising
/// together (P ∝ f², Γ or φ0 ∝ f), on elements of 5e−4 a at the contact ends growing by 8 % to
/// 1e−2 a inside; `electric` is the charge Γ or the potential φ0 at full load.
fn general_loaded(
    model: &fretsim::contact::ContactModel,
    normal_load: f64,
    electric: f64,
) -> (
    fretsim::contact::general::Solver,
    fretsim::contact::general::GeneralState,
) {
    use fretsim::contact::general::mesh::{Focus, Mesh};
    use fretsim::contact::general::{GeneralState, Loads, Options, Solver};
    let disc = Discretisation::new(64);
    let normal = solve_normal(model, &disc, normal_load, NormalOptions::default()).unwrap();
    let a = normal.state.half_width;
    let focus = [Focus {
        at: a,
        size: 5e-4 * a,
    }];
    let solver = Solver::new(
        model,
        Mesh::symmetric(1.1 * a, &focus, 1.08, 1e-2 * a),
        Options::default(),
    );
    let mut state = GeneralState::unloaded(solver.mesh().clone());
    for k in 1..=20 {
        let f = k as f64 / 20.0;
        let loads = Loads {
            normal: normal_load * f * f,
            tangential: 0.0,
            electric: electric * f,
            bulk_stress: 0.0,
        };
        state = solver.step(&state, loads).unwrap().0;
    }
    (solver, state)
}

/// 20 consecutive general steps from `state`: Q up to 0.5 ηP in steps of 0.05 ηP and back
/// down to 0, each from the previous state.
fn general_history(
    solver: &fretsim::contact::general::Solver,
    state: &fretsim::contact::general::GeneralState,
    friction: f64,
) -> fretsim::contact::general::GeneralState {
    use fretsim::contact::general::Loads;
    let eta_p = friction * state.loads.normal;
    let mut s = state.clone();
    for k in 1..=20_i32 {
        let q = 0.05 * eta_p * f64::from(10 - (10 - k).abs());
        s = solver
            .step(
                &s,
                Loads {
                    tangential: q,
                    ..s.loads
                },
            )
            .unwrap()
            .0;
    }
    s
}

/// The general element solver on the default contact (PZT-4, conducting punch, η = 0.3,
/// P = 2000 N/m; [`general_loaded`]). `general/tangential_step` takes Q from 0 to 0.05 ηP in
/// one step (issue 37's target for it is 20 ms); `general/history_20_steps` runs
/// [`general_history`] (divide by 20 for the cost of a step). `general/strong_coupling_20_steps`
/// runs the same history on the contacts where the electric coupling is strongest, at
/// η = 0.5: the punch at the potential φ0 = −86.10 V (`potential`, the potential of the charge
/// 2Γ1) and the punch carrying Γ = 1.5Γ1 = 7.503e−7 C/m (`charge_1.5G1`).
fn general_step(c: &mut Criterion) {
    use fretsim::contact::Electrode;
    use fretsim::contact::general::Loads;
    let sc = default_scenario();
    let (solver, state) = general_loaded(&sc.model, sc.normal_load, 6e-7);
    let eta_p = sc.model.friction * sc.normal_load;
    let mut g = c.benchmark_group("general/tangential_step");
    g.sample_size(10);
    g.bench_function(BenchmarkId::from_parameter(solver.mesh().len()), |b| {
        b.iter(|| {
            let loads = Loads {
                tangential: 0.05 * eta_p,
                ..state.loads
            };
            black_box(solver.step(&state, loads).unwrap())
        })
    });
    g.finish();
    let mut g = c.benchmark_group("general/history_20_steps");
    g.sample_size(10);
    g.bench_function(BenchmarkId::from_parameter(solver.mesh().len()), |b| {
        b.iter(|| black_box(general_history(&solver, &state, sc.model.friction)))
    });
    g.finish();
    let mut g = c.benchmark_group("general/strong_coupling_20_steps");
    g.sample_size(10);
    for (name, electrode, electric) in [
        (
            "potential",
            Electrode::ConductingPotential { potential: -86.10 },
            -86.10,
        ),
        (
            "charge_1.5G1",
            Electrode::ConductingCharge { charge: 7.503e-7 },
            7.503e-7,
        ),
    ] {
        let mut model = sc.model.clone();
        model.electrode = electrode;
        model.friction = 0.5;
        let (solver, state) = general_loaded(&model, sc.normal_load, electric);
        g.bench_function(BenchmarkId::from_parameter(name), |b| {
            b.iter(|| black_box(general_history(&solver, &state, model.friction)))
        });
    }
    g.finish();
}

/// One cycle of P and Q in phase (`scenarios/normal_load_in_phase.json`, 40 steps, each on a
/// mesh made for its contact), against the same cycle of Q at constant P taken by the general
/// solver (40 steps on one mesh): the cost of a step that changes P; and one cycle of
/// displacement control into gross slip (`scenarios/displacement_gross_slip.json`, 40
/// steps, half of them on the Coulomb plateau).
fn load_paths(c: &mut Criterion) {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/normal_load_in_phase.json"
    ))
    .unwrap();
    let in_phase = text.replace(r#""repeats": 4"#, r#""repeats": 1"#);
    let constant = in_phase
        .replace(", 2840.0]", ", 2240.0]")
        .replace(", 1640.0]", ", 2240.0]")
        .replace(
            r#""normal_load": 2240.0,"#,
            r#""normal_load": 2240.0, "numerics": {"solver": "general"},"#,
        );
    let gross = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/displacement_gross_slip.json"
    ))
    .unwrap()
    .replace(r#""repeats": 3"#, r#""repeats": 1"#)
    .replace(r#""steps_per_segment": 20"#, r#""steps_per_segment": 10"#);
    let mut g = c.benchmark_group("load_paths/cycle");
    g.sample_size(10);
    for (name, text) in [
        ("in_phase_p", in_phase),
        ("constant_p", constant),
        ("gross_slip", gross),
    ] {
        let raw = fretsim::parse(&text, std::path::Path::new("bench.json")).unwrap();
        let sc = fretsim::validate(raw).unwrap();
        g.bench_function(BenchmarkId::from_parameter(name), |b| {
            b.iter(|| {
                black_box(fretsim::io::solve(&sc, &mut fretsim::history::NoObserver).unwrap())
            })
        });
    }
    g.finish();
}

/// A whole run in memory, with its outputs' analyses (cycles, fatigue indicators on the field
/// grid): the first 40 reversals of `benches/scenarios/random_variable_amplitude_100.json`
/// (the default contact, random amplitudes 0.1–0.7 ηP, 292 steps) under `auto`, where the
/// spectral solver takes the steps and the general solver checks each phase's first, and
/// under `general`, where the general solver takes every step: a history that the general
/// solver holds costs their ratio (issue 37's flat-cost measurement).
fn random_history(c: &mut Criterion) {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/benches/scenarios/random_variable_amplitude_100.json"
    ))
    .unwrap();
    let mut raw: serde_json::Value = serde_json::from_str(&text).unwrap();
    let points = raw["tangential_history"]["points"].as_array_mut().unwrap();
    points.truncate(41);
    let mut g = c.benchmark_group("run/random_history_40_reversals");
    g.sample_size(10);
    for solver in ["auto", "general"] {
        raw["numerics"] = serde_json::json!({ "solver": solver });
        let text = raw.to_string();
        let sc =
            fretsim::validate(fretsim::parse(&text, std::path::Path::new("bench.json")).unwrap())
                .unwrap();
        g.bench_function(BenchmarkId::from_parameter(solver), |b| {
            b.iter(|| {
                black_box(fretsim::io::solve(&sc, &mut fretsim::history::NoObserver).unwrap())
            })
        });
    }
    g.finish();
}

criterion_group!(
    benches,
    random_history,
    load_paths,
    general_step,
    kernels,
    normal,
    steps,
    steps_in_a_run,
    recalled,
    reversal,
    cycle,
    steady_cycle
);
criterion_main!(benches);
