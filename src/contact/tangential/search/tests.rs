use super::super::tests::{advance_driver, forward_problem};
use super::*;

/// The coarse grid's Jacobian of a forward step (default scenario, first loading, at
/// 0.3 ηP) is the fine grid's to within a few per cent, and nearer to it than the fine
/// Jacobian of the previous step (0.25 ηP), which is what carrying a Jacobian from step to
/// step starts from. The measure is the largest entry of `J_start⁻¹ J − I`, the factor by
/// which a quasi-Newton step from `J_start` misses. Measured at M = 72, 80, 96, 112, 128,
/// 192 and 256: coarse 9.0e−3, 1.6e−2, 2.7e−2, 9.4e−3, 9.1e−3, 2.1e−2 and 9.2e−3; the
/// previous step's 6.7e−2 to 8.7e−2, at least 2.5 times the coarse one. Bounds, at M = 80,
/// 96 and 128: 4e−2, and twice the coarse one.
#[test]
fn coarse_jacobian_is_near_the_fine_one() {
    use crate::contact::normal::{NormalOptions, solve_normal};
    use crate::history::{DriverState, LoadPoint};
    let sc = crate::scenario::default_scenario();
    let limit = sc.model.friction * sc.normal_load;
    for m in [80, 96, 128] {
        let disc = Discretisation::new(m);
        let normal =
            solve_normal(&sc.model, &disc, sc.normal_load, NormalOptions::default()).unwrap();
        let mut driver = DriverState::after_normal_loading(&normal);
        let base = normal.state.traction.stick.clone().map(Arc::new);
        let maps = RefCell::default();
        // The fine Jacobian at the state the driver has reached, and the step's problem.
        let at_state = |driver: &DriverState| {
            let state = &driver.state;
            let g = Geometry::of(state).expect("slip state");
            let problem = forward_problem(&sc, &disc, driver, base.as_ref(), &maps);
            let (r, solved, _) = problem.evaluate(&g, state, INNER_TOLERANCE).unwrap();
            // The state is a converged one: its residual again below the solver's tolerance.
            let tolerance = SlipOptions::default().tolerance;
            assert!(norm(&r) < tolerance, "M = {m}: residual {:e}", norm(&r));
            let fine = fd_jacobian(&problem, &g, &r, &solved).unwrap();
            let coarse = coarse_jacobian(&problem, &g, &solved).expect("coarse grid");
            (fine, coarse)
        };
        // Largest entry of `start⁻¹ j − I` (`solve4` solves `J dx = −r`).
        let miss = |start: [[f64; 4]; 4], j: [[f64; 4]; 4]| {
            (0..4)
                .map(|k| {
                    let column = std::array::from_fn(|i| j[i][k]);
                    let x = solve4(start, column).expect("regular");
                    (0..4)
                        .map(|i| (-x[i] - if i == k { 1.0 } else { 0.0 }).abs())
                        .fold(0.0, f64::max)
                })
                .fold(0.0, f64::max)
        };
        let mut previous = None;
        for step in 1..=6 {
            let point = LoadPoint {
                step,
                t: step as f64,
                q: 0.05 * step as f64 * limit,
                punch: None,
            };
            advance_driver(&sc, &disc, &mut driver, point);
            if step >= 5 {
                let (fine, coarse) = at_state(&driver);
                if let Some(carried) = previous {
                    let (coarse_miss, carried_miss) = (miss(coarse, fine), miss(carried, fine));
                    println!("M = {m}: coarse {coarse_miss:.2e}, previous {carried_miss:.2e}");
                    assert!(coarse_miss < 4e-2, "M = {m}: coarse {coarse_miss:e}");
                    assert!(carried_miss > 2.0 * coarse_miss, "M = {m}");
                }
                previous = Some(fine);
            }
        }
    }
}

/// A step's bound on its residual evaluations (`SlipOptions::step_evaluations`, with the
/// options of `numerics.solver = auto`) counts the evaluations the step reports: a bound of
/// the evaluations a step needs leaves it as it is, to the bit; a bound of one ends the
/// step after the first residual of its first attempt, with that attempt's failure.
#[test]
fn the_evaluation_bound_ends_a_step_and_changes_none_within_it() {
    use crate::history::{LoadPoint, RunOptions, SolverChoice, Tried, try_step};
    let sc = crate::scenario::default_scenario();
    let disc = Discretisation::new(64);
    let limit = sc.model.friction * sc.normal_load;
    let mut driver = crate::history::driver_after_normal_loading(&sc, &disc);
    let point = |step: usize| LoadPoint {
        step,
        t: step as f64,
        q: 0.05 * step as f64 * limit,
        punch: None,
    };
    for step in 1..=3 {
        advance_driver(&sc, &disc, &mut driver, point(step));
    }
    let auto = RunOptions::new(SolverChoice::Auto).slip;
    let solve = |bound| {
        let options = SlipOptions {
            step_evaluations: bound,
            ..auto
        };
        match try_step(&sc.model, &disc, &driver, point(4), options) {
            Ok(Tried::Slip(trial)) => Ok(trial.solved),
            Ok(Tried::Hold(_)) => panic!("a slip step"),
            Err(failure) => Err(failure.failure),
        }
    };
    let free = solve(None).expect("the step converges");
    let needed = free.newton_iterations;
    assert!(needed > 1, "{needed} evaluations");
    let bounded = solve(Some(needed)).expect("within its bound");
    assert_eq!(bounded.newton_iterations, needed);
    let bits = |s: &SlipStep| {
        let zone = s.state.traction.stick.as_ref().expect("stick zone");
        [zone.lo, zone.hi, s.state.half_width, s.state.centre, s.residual].map(f64::to_bits)
    };
    assert_eq!(bits(&bounded), bits(&free));
    match solve(Some(1)) {
        Err(SolveFailure::NoConvergence { iterations, .. }) => assert_eq!(iterations, 1),
        other => panic!("{other:?}"),
    }
}

/// The order in which a step's attempts are made: at a phase start every pattern with
/// the continued guesses, then every pattern with the jumps; within a phase the
/// standard pattern with both first.
#[test]
fn the_attempt_plan_is_pinned() {
    use SlipPattern::{Forward, Inward, Outward, Reverse};
    let (warm, jump) = ((1.0, 2.0), (3.0, 4.0));
    let start = attempt_plan(1.0, false, &[warm], &[jump]);
    assert_eq!(
        start,
        [
            (Forward, warm),
            (Inward, warm),
            (Outward, warm),
            (Forward, jump),
            (Inward, jump),
            (Outward, jump),
        ]
    );
    let within = attempt_plan(-1.0, true, &[warm], &[jump]);
    assert_eq!(
        within,
        [
            (Reverse, warm),
            (Reverse, jump),
            (Inward, warm),
            (Inward, jump),
            (Outward, warm),
            (Outward, jump),
        ]
    );
    for pattern in [Forward, Reverse, Inward, Outward] {
        assert_eq!(SlipPattern::of_signs(pattern.signs()), pattern);
    }
}
