//! Criterion benches of the numerical core, parameterised by the number of collocation nodes M.
//! Run with `cargo bench` (not run in CI). No file I/O, no progress bars.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use fretsim::contact::normal::{NormalOptions, solve_normal};
use fretsim::contact::pressure::Discretisation;
use fretsim::contact::tangential::SlipOptions;
use fretsim::history::{DriverState, LoadHistory, LoadPoint, NoObserver, advance, run_history};
use fretsim::scenario::default_scenario;

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
    for m in [32, 64, 128] {
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

fn steps(c: &mut Criterion) {
    let sc = default_scenario();
    let lim = sc.model.friction * sc.normal_load;
    let mut forward = c.benchmark_group("solve/forward_step");
    forward.sample_size(10);
    for m in [32, 64, 128] {
        let disc = Discretisation::new(m);
        let normal =
            solve_normal(&sc.model, &disc, sc.normal_load, NormalOptions::default()).unwrap();
        // A state in the middle of the first forward phase, then one more step.
        let mut driver = DriverState::after_normal_loading(&normal);
        for (i, q) in [0.1, 0.2, 0.3].iter().enumerate() {
            let point = LoadPoint {
                step: i + 1,
                t: i as f64,
                q: q * lim,
            };
            advance(
                &sc.model,
                &disc,
                &mut driver,
                point,
                SlipOptions::default(),
                &mut NoObserver,
            )
            .unwrap();
        }
        forward.bench_with_input(BenchmarkId::from_parameter(m), &m, |b, _| {
            b.iter(|| {
                let mut d = driver.clone();
                let point = LoadPoint {
                    step: 4,
                    t: 4.0,
                    q: 0.35 * lim,
                };
                black_box(
                    advance(
                        &sc.model,
                        &disc,
                        &mut d,
                        point,
                        SlipOptions::default(),
                        &mut NoObserver,
                    )
                    .unwrap(),
                )
            })
        });
    }
    forward.finish();
}

fn reversal(c: &mut Criterion) {
    let sc = default_scenario();
    let lim = sc.model.friction * sc.normal_load;
    let mut g = c.benchmark_group("solve/reversal_step");
    g.sample_size(10);
    for m in [32, 64] {
        let disc = Discretisation::new(m);
        let normal =
            solve_normal(&sc.model, &disc, sc.normal_load, NormalOptions::default()).unwrap();
        let mut driver = DriverState::after_normal_loading(&normal);
        for i in 1..=10 {
            let point = LoadPoint {
                step: i,
                t: i as f64,
                q: 0.05 * i as f64 * lim,
            };
            advance(
                &sc.model,
                &disc,
                &mut driver,
                point,
                SlipOptions::default(),
                &mut NoObserver,
            )
            .unwrap();
        }
        g.bench_with_input(BenchmarkId::from_parameter(m), &m, |b, _| {
            b.iter(|| {
                let mut d = driver.clone();
                let point = LoadPoint {
                    step: 11,
                    t: 11.0,
                    q: 0.45 * lim,
                };
                black_box(
                    advance(
                        &sc.model,
                        &disc,
                        &mut d,
                        point,
                        SlipOptions::default(),
                        &mut NoObserver,
                    )
                    .unwrap(),
                )
            })
        });
    }
    g.finish();
}

fn cycle(c: &mut Criterion) {
    let sc = default_scenario();
    let lim = sc.model.friction * sc.normal_load;
    let mut g = c.benchmark_group("cycle/normal_plus_one_cycle");
    g.sample_size(10);
    for m in [32, 64] {
        let disc = Discretisation::new(m);
        let normal =
            solve_normal(&sc.model, &disc, sc.normal_load, NormalOptions::default()).unwrap();
        let history = LoadHistory {
            points: vec![
                (0.0, 0.0),
                (1.0, 0.5 * lim),
                (3.0, -0.5 * lim),
                (5.0, 0.5 * lim),
            ],
            steps_per_segment: 10,
            max_step: 0.05 * lim,
        };
        g.bench_with_input(BenchmarkId::from_parameter(m), &m, |b, _| {
            b.iter(|| {
                black_box(run_history(
                    &sc.model,
                    &disc,
                    &normal,
                    &history,
                    SlipOptions::default(),
                    &mut NoObserver,
                ))
            })
        });
    }
    g.finish();
}

criterion_group!(benches, kernels, normal, steps, reversal, cycle);
criterion_main!(benches);
