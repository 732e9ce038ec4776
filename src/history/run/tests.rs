//! Tests of the hybrid driver's take-backs (`super`): a closed loop continued, a turning point
//! the general solver took replayed, and the distance of two states' shear tractions.

use super::*;
use crate::contact::general::Recall;
use crate::history::checks::turning_checked;
use crate::history::driver::advance;
use crate::history::general::INNER_SIZE;

/// The uncoupled contact of `scenarios/cattaneo_mindlin_uncoupled.json` (ν = 0.5).
fn uncoupled() -> crate::scenario::Scenario {
    let text = include_str!("../../../scenarios/cattaneo_mindlin_uncoupled.json");
    let raw = crate::scenario::parse(text, std::path::Path::new("cm.json")).unwrap();
    crate::scenario::validate(raw).unwrap()
}

fn at(step: usize, q: f64) -> LoadPoint {
    LoadPoint {
        step,
        t: step as f64,
        q,
        punch: None,
    }
}

/// The spectral solver's first loading of `sc` in `steps` steps of 0.05ηP.
fn first_loading(
    sc: &crate::scenario::Scenario,
    disc: &Discretisation,
    steps: usize,
) -> DriverState {
    let (model, options) = (&sc.model, SlipOptions::default());
    let limit = model.friction * sc.normal_load;
    let mut driver = crate::history::driver_after_normal_loading(sc, disc);
    for k in 1..=steps {
        let point = at(k, 0.05 * k as f64 * limit);
        advance(model, disc, &mut driver, point, options, &mut NoObserver).unwrap();
    }
    driver
}

/// `sc` loaded to 0.5ηP by the spectral solver, then by the general solver through `loads`
/// (fractions of ηP): the spectral driver at 0.5ηP, the general run, and the last step's
/// point and record.
fn handed_over(
    sc: &crate::scenario::Scenario,
    disc: &Discretisation,
    loads: &[f64],
) -> (DriverState, GeneralRun, (LoadPoint, StepRecord)) {
    let limit = sc.model.friction * sc.normal_load;
    let driver = first_loading(sc, disc, 10);
    let mut recall = Recall::new(false);
    let mut run = GeneralRun::handover(&sc.model, &driver, INNER_SIZE, &mut recall);
    let mut last = None;
    for (k, q) in loads.iter().enumerate() {
        let point = at(11 + k, q * limit);
        last = Some((point, run.step(&sc.model, point, &mut recall).unwrap()));
    }
    (driver, run, last.expect("a general step"))
}

/// The stick zone's half-width over the contact's, c/a.
fn stick_ratio(driver: &DriverState) -> f64 {
    let state = &driver.state;
    let stick = state.traction.stick.as_ref().expect("a stick zone");
    0.5 * (stick.hi - stick.lo) / state.half_width
}

/// Loaded to Q1 = 0.5ηP by the spectral solver, then down to −0.5ηP and up again by the
/// general solver: the step that passes Q1 closes the loop, and Mindlin–Deresiewicz (exact
/// on this uncoupled contact) puts the state back on the first loading. The spectral
/// solver continues its turning state at Q1 to the step's load, its state agrees with the
/// general solver's, and its stick zone is Cattaneo–Mindlin's,
/// `c/a = √(1 − Q/(ηP))`, to the spectral solver's resolution. The same try at the step
/// before, whose loop is still open (the rising branch from −0.5ηP), is refused.
#[test]
fn a_closed_loop_is_taken_back_as_the_first_loading_continued() {
    let sc = uncoupled();
    let disc = Discretisation::new(sc.collocation_points);
    let (model, options) = (&sc.model, SlipOptions::default());
    let limit = model.friction * sc.normal_load;
    let loads: Vec<f64> = (1..=20)
        .map(|k| 0.5 - 0.05 * k as f64)
        .chain((1..=21).map(|k| -0.5 + 0.05 * k as f64))
        .collect();
    // At 0.45ηP: the loop is open.
    let (turning, run, (point, record)) = handed_over(&sc, &disc, &loads[..40]);
    let before = (point, &record, 0.4 * limit);
    let open = continues(model, &disc, (turning, &[]), &run, before, options);
    assert!(open.is_none(), "an open loop was taken back");
    let (turning, run, (point, record)) = handed_over(&sc, &disc, &loads);
    let before = (point, &record, 0.5 * limit);
    let closed = continues(model, &disc, (turning, &[]), &run, before, options)
        .expect("the closed loop is taken back");
    let c_over_a = stick_ratio(&closed);
    let exact = (1.0 - point.q / limit).sqrt();
    println!(
        "c/a {c_over_a:.8} against {exact:.8} ({:.1e})",
        c_over_a - exact
    );
    assert_eq!(closed.phase, record.phase);
    // Measured 1.9e−14: the spectral solver's Cattaneo–Mindlin state is exact here.
    assert!((c_over_a - exact).abs() < 1e-10, "{c_over_a} {exact}");
}

/// Past the mirror of the first turning point (0 → 0.5ηP by the spectral solver, down to
/// −0.6ηP by the general solver) the contact is on the first loading in the other direction
/// (Mindlin–Deresiewicz: unloading from Q* meets it at −Q*), which goes on from the start's
/// state, the end of the normal loading: Cattaneo–Mindlin's `c/a = √(1 − |Q|/(ηP))`.
#[test]
fn past_the_mirror_of_the_first_turning_point_the_first_loading_goes_on_from_the_start() {
    let sc = uncoupled();
    let disc = Discretisation::new(sc.collocation_points);
    let (model, options) = (&sc.model, SlipOptions::default());
    let limit = model.friction * sc.normal_load;
    let loads: Vec<f64> = (1..=22).map(|k| 0.5 - 0.05 * k as f64).collect();
    let (_, run, (point, record)) = handed_over(&sc, &disc, &loads);
    let start = crate::history::driver_after_normal_loading(&sc, &disc);
    let before = (point, &record, -0.55 * limit);
    let continued = continues(model, &disc, (start, &[]), &run, before, options)
        .expect("the first loading goes on");
    let c_over_a = stick_ratio(&continued);
    let exact = (1.0 - 0.6_f64).sqrt();
    println!(
        "c/a {c_over_a:.8} against {exact:.8} ({:.1e})",
        c_over_a - exact
    );
    assert_eq!(continued.phase, record.phase);
    assert!((c_over_a - exact).abs() < 1e-10, "{c_over_a} {exact}");
}

/// `Solver::traction_distance` between two Cattaneo–Mindlin states of the first loading
/// (uncoupled contact, Q1 = 0.5ηP and Q2 = 0.3ηP): q1 − q2 ≥ 0 everywhere, so the L1 norm
/// of the difference is its integral, (Q1 − Q2)/(ηP) = 0.2, and p does not change.
#[test]
fn the_shear_distance_of_two_cattaneo_mindlin_states_is_their_load_difference() {
    let sc = uncoupled();
    let disc = Discretisation::new(sc.collocation_points);
    let driver = first_loading(&sc, &disc, 10);
    let mut recall = Recall::new(false);
    let at_q2 = first_loading(&sc, &disc, 6);
    let run = GeneralRun::handover(&sc.model, &at_q2, INNER_SIZE, &mut recall);
    let [pressure, shear] = run.solver().traction_distance(&driver.state, &run.state);
    println!("distances: p {pressure:.2e}, q {shear:.10} (exact 0.2)");
    // Measured: p 0 and q − 0.2 = −5.0e−7, the element means' Gauss–Legendre rule across
    // the square-root kinks at the stick ends.
    assert!(
        pressure < 1e-12 && (shear - 0.2).abs() < 2e-6,
        "{pressure} {shear}"
    );
}

/// The general solver's check of a turning point (`turning_checked`), uncoupled contact. The
/// spectral solver's step from 0.45ηP to Q = 0.5ηP on the first loading agrees with it. The
/// Mindlin–Deresiewicz state at the same load, unloaded from Q* = 0.7ηP (which the spectral
/// solver holds exactly here), put forward as that step's state is contradicted and the step
/// handed over: with ξ = x/a, c1² = 0.5, c'² = 1 − (Q* − Q)/(2ηP) = 0.9 and c*² = 0.3, the
/// difference of the two shear tractions is
/// `ηp0 [2√(1 − ξ²) − c1√(1 − ξ²/c1²) − 2c'√(1 − ξ²/c'²) + c*√(1 − ξ²/c*²)]` (each root
/// taken as 0 outside its zone), and its L1 norm over ηP = ηp0πa/2 is computed here by the
/// midpoint rule.
#[test]
fn a_turning_state_with_another_memory_is_handed_over_at_the_turning_point() {
    let sc = uncoupled();
    let disc = Discretisation::new(sc.collocation_points);
    let (model, options) = (&sc.model, RunOptions::new(SolverChoice::Auto));
    let limit = model.friction * sc.normal_load;
    let before = first_loading(&sc, &disc, 9);
    let point = at(10, 0.5 * limit);
    let mut recall = Recall::new(false);
    let first = first_loading(&sc, &disc, 10);
    let agrees = turning_checked(model, &before, (point, options), &first.state, &mut recall);
    assert!(agrees.is_none(), "the first loading was contradicted");
    let mut unloaded = first_loading(&sc, &disc, 14);
    for k in 1..=4 {
        let point = at(14 + k, (0.7 - 0.05 * k as f64) * limit);
        advance(
            model,
            &disc,
            &mut unloaded,
            point,
            options.slip,
            &mut NoObserver,
        )
        .unwrap();
    }
    let Some((failure, taken)) = turning_checked(
        model,
        &before,
        (point, options),
        &unloaded.state,
        &mut recall,
    ) else {
        panic!("the unloaded state was not contradicted");
    };
    let [_, shear] = (taken.0.solver()).traction_distance(&unloaded.state, &taken.0.state);
    let root = |xi: f64, c: f64| c * (1.0 - (xi / c).powi(2)).max(0.0).sqrt();
    let (c1, c_half, c_star) = (0.5f64.sqrt(), 0.9f64.sqrt(), 0.3f64.sqrt());
    let n = 200_000;
    let exact = (0..n)
        .map(|i| {
            let xi = -1.0 + (i as f64 + 0.5) * 2.0 / n as f64;
            (2.0 * root(xi, 1.0) - root(xi, c1) - 2.0 * root(xi, c_half) + root(xi, c_star)).abs()
        })
        .sum::<f64>()
        * (2.0 / n as f64)
        / (0.5 * std::f64::consts::PI);
    println!("{}: {shear:.6} against {exact:.6}", failure.failure);
    assert_eq!(taken.1.step, point.step);
    // Measured: 0.195164 against 0.195108, the general solver's Cattaneo–Mindlin stick end
    // within an element of the default mesh.
    assert!((shear - exact).abs() < 1e-4, "{shear} {exact}");
}

/// The replay's turning points (`Turnings::replay`): from the start's state (the end of
/// the normal loading) when no later one is kept, which is also what a load past the mirror
/// of the first turning point continues; after 1, 2, 3, … failures in a row it
/// waits 1, 3, 7, … turning points, at most 31, and after one taken it does not wait.
#[test]
fn a_replay_starts_from_the_start_and_waits_longer_after_each_failure() {
    let sc = uncoupled();
    let disc = Discretisation::new(sc.collocation_points);
    let driver = crate::history::driver_after_normal_loading(&sc, &disc);
    let mut turnings = Turnings::new(0.0, Some(&driver));
    turnings.step(0.0, 1.0);
    turnings.end_phase(1.0, None);
    turnings.step(1.0, -0.5);
    let (base, loads) = turnings.replay().expect("the start's state is kept");
    assert!(base.phase_sign.is_none() && base.phase == 0);
    assert_eq!(loads, vec![1.0]);
    let mut waits = Vec::new();
    for _ in 0..7 {
        turnings.replayed(false);
        let mut wait = 0;
        while turnings.replay().is_none() {
            wait += 1;
        }
        waits.push(wait);
    }
    assert_eq!(waits, [1, 3, 7, 15, 31, 31, 31]);
    turnings.replayed(true);
    assert!(turnings.replay().is_some());
    // Past the mirror −1 of the first turning point: the start's state goes on.
    let continued = turnings.step(-0.5, -1.5).expect("the start's state");
    assert!(continued.phase_sign.is_none() && turnings.loads() == vec![0.0]);
}

/// Loaded to R1 = 0.5ηP by the spectral solver, then by the general solver down to
/// R2 = −0.3ηP (a turning point it took) and up to Q = 0.2ηP: the spectral solver rebuilds
/// its state from the reduced history, its turning state at R1 stepped through R2 and on
/// to Q. Mindlin–Deresiewicz (exact on this uncoupled contact) gives the reloading stick
/// zone `c/a = √(1 − (Q − R2)/(2ηP))`; the replayed state agrees with the general
/// solver's and has it to the spectral solver's resolution. Replayed without R2 (from R1
/// straight down to Q, an unloading stick zone √(1 − (R1 − Q)/(2ηP)) = 0.922 against
/// 0.866), it is refused.
#[test]
fn a_turning_point_the_general_solver_took_is_replayed_from_the_reduced_history() {
    let sc = uncoupled();
    let disc = Discretisation::new(sc.collocation_points);
    let (model, options) = (&sc.model, SlipOptions::default());
    let limit = model.friction * sc.normal_load;
    let loads: Vec<f64> = (1..=16)
        .map(|k| 0.5 - 0.05 * k as f64)
        .chain((1..=10).map(|k| -0.3 + 0.05 * k as f64))
        .collect();
    let (turning, run, (point, record)) = handed_over(&sc, &disc, &loads);
    let before = (point, &record, 0.15 * limit);
    let replay = |targets: &[f64]| {
        continues(
            model,
            &disc,
            (turning.clone(), targets),
            &run,
            before,
            options,
        )
    };
    assert!(
        replay(&[]).is_none(),
        "replayed without the turning point R2"
    );
    let replayed = replay(&[-0.3 * limit]).expect("the reduced history is replayed");
    let c_over_a = stick_ratio(&replayed);
    let exact = (1.0 - (0.2 + 0.3) / 2.0_f64).sqrt();
    println!(
        "c/a {c_over_a:.8} against {exact:.8} ({:.1e})",
        c_over_a - exact
    );
    assert_eq!(replayed.phase, record.phase);
    assert!((c_over_a - exact).abs() < 1e-10, "{c_over_a} {exact}");
}
