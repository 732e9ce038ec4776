//! The reference path against the fast path: the default scenario's history solved with every
//! speed-up of `Accelerations` off (and the normal-loading zone untabulated) and with all of
//! them on, step by step.

use fretsim::contact::ZoneTables;
use fretsim::contact::normal::{NormalOptions, solve_normal};
use fretsim::contact::pressure::Discretisation;
use fretsim::contact::tangential::{Accelerations, SlipOptions};
use fretsim::history::{NoObserver, RunOptions, StepRecord, run_history};

/// The default scenario's whole history (normal loading, then 0 → +½ηP and three ±½ηP
/// cycles, 130 steps at M = 64) with the given speed-ups, as the command runs it.
fn default_run(accelerations: Accelerations, zone_tables: ZoneTables) -> Vec<StepRecord> {
    let sc = fretsim::scenario::default_scenario();
    let disc = Discretisation::new(sc.collocation_points);
    let normal_options = NormalOptions {
        zone_tables,
        ..NormalOptions::default()
    };
    let normal = fretsim::history::NormalEnd::Spectral(Box::new(
        solve_normal(&sc.model, &disc, sc.normal_load, normal_options).unwrap(),
    ));
    let mut options = RunOptions::new(sc.solver);
    options.slip.accelerations = accelerations;
    let history = sc
        .history
        .as_ref()
        .expect("the default scenario has a history");
    run_history(&sc.model, &disc, &normal, history, options, &mut NoObserver)
        .unwrap()
        .records
}

/// The largest differences between two runs of the same steps, per quantity: the stick ends,
/// the half-width a and the eccentricity (relative to a), δ (relative to its range over the
/// run) and the step dissipation (relative to the largest). The steps must match in number,
/// phase, regime and slip signs.
fn differences(one: &[StepRecord], other: &[StepRecord]) -> [f64; 5] {
    assert_eq!(one.len(), other.len());
    let range = |f: fn(&StepRecord) -> f64| {
        let (lo, hi) = other
            .iter()
            .map(f)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |m, v| {
                (m.0.min(v), m.1.max(v))
            });
        hi - lo
    };
    let delta_range = range(|r| r.displacement);
    let largest = other.iter().map(|r| r.dissipation).fold(0.0, f64::max);
    let mut worst = [0.0_f64; 5];
    for (r, s) in one.iter().zip(other) {
        assert_eq!(
            (
                r.step,
                r.phase,
                r.regime,
                r.left_slip_sign,
                r.right_slip_sign
            ),
            (
                s.step,
                s.phase,
                s.regime,
                s.left_slip_sign,
                s.right_slip_sign
            )
        );
        let a = s.half_width;
        let d = [
            (r.stick_lo - s.stick_lo)
                .abs()
                .max((r.stick_hi - s.stick_hi).abs())
                / a,
            (r.half_width - s.half_width).abs() / a,
            (r.eccentricity - s.eccentricity).abs() / a,
            (r.displacement - s.displacement).abs() / delta_range,
            (r.dissipation - s.dissipation).abs() / largest,
        ];
        for (w, d) in worst.iter_mut().zip(d) {
            *w = w.max(d);
        }
    }
    worst
}

/// Residual evaluations of a run's steps.
fn evaluations(records: &[StepRecord]) -> usize {
    records.iter().map(|r| r.newton_iterations).sum()
}

/// The fast path (every speed-up on, the command's default) reaches the reference path's
/// states (every speed-up off: no recall, no carried or coarse Jacobians, no start guesses
/// from earlier phases, Broyden's updates, no tables of the stick zones' chains, no fade
/// table reused) over the default scenario's whole coupled history, and takes fewer residual
/// evaluations.
///
/// Measured on the project machine (AVX2 with FMA): the stick ends within 1.4e−11 a, a and
/// the eccentricity within 2.1e−12 a, δ within 9.6e−12 of its range, the step dissipations
/// within 1.5e−10 of the largest; 440 residual evaluations on the fast path, 803 on the
/// reference path. The bounds are those of two solution paths to one state
/// (`assert_same_states` in `reference.rs`): the solver's tolerance (1e−11 on the norm of
/// the four dimensionless residuals) bounds the geometry and δ to a few times it and the
/// step dissipations to some ten times it, so ten and a hundred times it. What the tables'
/// interpolation and the reused fade tables add (their own docs in `contact::stick_zone` and
/// `contact::inherited`) stays below that here.
#[test]
fn the_fast_path_reaches_the_reference_states() {
    let fast = default_run(Accelerations::default(), ZoneTables::default());
    let none = ZoneTables { chain: false };
    let reference = default_run(Accelerations::none(), none);
    let [ends, a, c, delta, dissipation] = differences(&fast, &reference);
    let (fast_evaluations, reference_evaluations) = (evaluations(&fast), evaluations(&reference));
    println!(
        "stick ends {ends:.2e} a, half-width {a:.2e} a, eccentricity {c:.2e} a, δ {delta:.2e} \
         of its range, dissipation {dissipation:.2e} of the largest; evaluations: fast \
         {fast_evaluations}, reference {reference_evaluations}"
    );
    let tolerance = SlipOptions::default().tolerance;
    for (name, d) in [
        ("stick ends", ends),
        ("a", a),
        ("eccentricity", c),
        ("δ", delta),
    ] {
        assert!(d < 10.0 * tolerance, "{name}: {d:e}");
    }
    assert!(
        dissipation < 100.0 * tolerance,
        "dissipation {dissipation:e}"
    );
    assert!(fast_evaluations < reference_evaluations);
}

/// The default options are the fast path, and `Accelerations::none` switches every speed-up
/// off.
#[test]
fn the_default_options_are_the_fast_path() {
    assert_eq!(
        SlipOptions::default().accelerations,
        Accelerations::default()
    );
    let none = Accelerations::none();
    assert!(
        !(none.recall
            || none.coarse_jacobian
            || none.mixed_start_guesses
            || none.projected_updates
            || none.chain_tables
            || none.continuation
            || none.general_recall
            || none.concurrent_checks)
    );
}
