//! What each speed-up of `Accelerations` gains on a whole run: a scenario (the default one, or
//! `--scenario FILE`) solved as `fretsim run` solves it (normal loading and the whole history,
//! without writing), with every speed-up on, with each one off, and with all of them off (the
//! reference path); and the same with the spectral solver alone (`RunOptions::spectral`,
//! without the general solver's checks of the phase starts, which take most of the default run
//! and which no switch touches).
//!
//! The variants are timed in rounds, each round running every variant once in a rotated
//! order, so that a change of the host's load falls on all of them alike (on a shared host,
//! criterion's one-variant-after-another groups drifted by more than most gains); the table
//! gives each variant's median over the rounds, its difference from the all-on median, and
//! the run's residual evaluations (which do not depend on the host).
//!
//! ```sh
//! cargo bench --bench accelerations               # 15 rounds
//! cargo bench --bench accelerations -- --rounds 30
//! cargo bench --bench accelerations -- --m 256 --spectral   # another M, spectral solver only
//! # long histories (`benches/scenarios/`): 100 random reversals (PZT-4 default contact,
//! # amplitudes uniform in 0.1–0.7 ηP, seed 7, 5 steps a reversal) and 1,000 steady cycles
//! cargo bench --bench accelerations -- --scenario benches/scenarios/random_variable_amplitude_100.json \
//!     --only chain_tables,recall --rounds 9 --spectral
//! ```

use std::hint::black_box;
use std::time::Instant;

use fretsim::contact::ZoneTables;
use fretsim::contact::normal::{NormalOptions, solve_normal};
use fretsim::contact::pressure::Discretisation;
use fretsim::contact::tangential::Accelerations;
use fretsim::history::{NoObserver, NormalEnd, RunOptions, StepRecord, run_history};

/// The command's allocator (`src/main.rs`), so that the bench times what a run does.
#[cfg(feature = "mimalloc")]
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// A scenario (the default one unless `--scenario FILE`) solved with `accelerations` (the
/// normal-loading zone's tables with `chain_tables`), by the scenario's
/// solver choice or, with `spectral`, by the spectral solver alone, on `m` collocation points.
fn default_run(
    sc: &fretsim::Scenario,
    accelerations: Accelerations,
    spectral: bool,
    m: usize,
) -> Vec<StepRecord> {
    let disc = Discretisation::new(m);
    let normal_options = NormalOptions {
        zone_tables: ZoneTables {
            chain: accelerations.chain_tables,
        },
        ..NormalOptions::default()
    };
    let normal = NormalEnd::Spectral(Box::new(
        solve_normal(&sc.model, &disc, sc.normal_load, normal_options).unwrap(),
    ));
    let mut options = if spectral {
        RunOptions::spectral(Default::default())
    } else {
        RunOptions::new(sc.solver)
    };
    options.slip.accelerations = accelerations;
    let history = sc.history.as_ref().expect("a history");
    run_history(&sc.model, &disc, &normal, history, options, &mut NoObserver)
        .unwrap()
        .records
}

/// A switch of [`Accelerations`] turned off.
type SwitchOff = fn(&mut Accelerations);

/// Every speed-up on, each one off, and all off.
fn variants() -> Vec<(String, Accelerations)> {
    let on = Accelerations::default();
    let off: [(&str, SwitchOff); 8] = [
        ("recall", |a| a.recall = false),
        ("coarse_jacobian", |a| a.coarse_jacobian = false),
        ("mixed_start_guesses", |a| a.mixed_start_guesses = false),
        ("projected_updates", |a| a.projected_updates = false),
        ("chain_tables", |a| a.chain_tables = false),
        ("continuation", |a| a.continuation = false),
        ("general_recall", |a| a.general_recall = false),
        ("concurrent_checks", |a| a.concurrent_checks = false),
    ];
    let mut all = vec![("all on".to_string(), on)];
    for (name, switch_off) in off {
        let mut a = on;
        switch_off(&mut a);
        all.push((format!("without {name}"), a));
    }
    all.push(("reference (all off)".to_string(), Accelerations::none()));
    all
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let value = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1))
            .and_then(|n| n.parse().ok())
    };
    let rounds = value("--rounds").unwrap_or(15);
    let text = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    let sc = match text("--scenario") {
        Some(path) => fretsim::load(std::path::Path::new(&path)).expect("a valid scenario"),
        None => fretsim::scenario::default_scenario(),
    };
    let m = value("--m").unwrap_or(sc.collocation_points);
    // `--only a,b`: all on, the reference, and the variants without a or b.
    let only: Option<Vec<String>> =
        text("--only").map(|s| s.split(',').map(|w| format!("without {w}")).collect());
    let solvers: &[bool] = if args.iter().any(|a| a == "--spectral") {
        &[true]
    } else {
        &[false, true]
    };
    if args.iter().any(|a| a == "--list") {
        return;
    }
    let variants: Vec<(String, Accelerations)> = variants()
        .into_iter()
        .filter(|(name, _)| {
            only.as_ref()
                .is_none_or(|o| !name.starts_with("without") || o.iter().any(|w| w == name))
        })
        .collect();
    let n = variants.len();
    for &spectral in solvers {
        let solver = if spectral {
            "spectral solver alone"
        } else {
            "as `fretsim run`"
        };
        let evaluations: Vec<usize> = variants
            .iter()
            .map(|(_, a)| {
                default_run(&sc, *a, spectral, m)
                    .iter()
                    .map(|r| r.newton_iterations)
                    .sum()
            })
            .collect();
        let mut times = vec![Vec::new(); n];
        for round in 0..rounds {
            for k in 0..n {
                let v = (k + round) % n;
                let start = Instant::now();
                black_box(default_run(&sc, variants[v].1, spectral, m));
                times[v].push(start.elapsed().as_secs_f64() * 1e3);
            }
        }
        let medians: Vec<f64> = times.into_iter().map(median).collect();
        println!(
            "\n{} at M = {m}, {solver}: median of {rounds} rounds",
            sc.name
        );
        println!("| variant | median (ms) | − all on (ms) | residual evaluations |");
        println!("|---|---|---|---|");
        for ((name, _), (m, e)) in variants.iter().zip(medians.iter().zip(&evaluations)) {
            println!("| {name} | {m:.1} | {:+.1} | {e} |", m - medians[0]);
        }
    }
}
