//! A bulk stress σB ([`Loads::bulk_stress`]) against the closed form for a rigid punch
//! ([`crate::analytical::BulkStressCattaneo`]).

use super::*;
use crate::analytical::BulkStressCattaneo;

/// Mesh of `[−1.1a, 1.1a]`, size 1e−3·a at ±a and `stick·a` at the stick ends `e ± c`,
/// growing by 2 % per element up to 0.02a.
fn graded_at(a: f64, ends: [f64; 2], stick: f64) -> Mesh {
    let focus = [
        Focus {
            at: -a,
            size: 1e-3 * a,
        },
        Focus {
            at: ends[0],
            size: stick * a,
        },
        Focus {
            at: ends[1],
            size: stick * a,
        },
        Focus {
            at: a,
            size: 1e-3 * a,
        },
    ];
    Mesh::graded(-1.1 * a, 1.1 * a, &focus, 1.02, 0.02 * a)
}

fn with_bulk(normal: f64, tangential: f64, bulk_stress: f64) -> Loads {
    Loads {
        bulk_stress,
        ..loads(normal, tangential)
    }
}

/// The uncoupled cylinder (ν = ½) pressed to P, then Q and σB raised in proportion to
/// Q* = ηP/2 and σB* = 0.2ηp0 in four steps (|σB*|/p0 = 0.06 ≤ Q*/P = 0.15: the stick zones
/// nest and slip never reverses): one stick zone between slip zones of one direction, its
/// centre at e = aσB/(2ηp0) = 0.1a (towards +x) and half-width c = a√(1 − Q/(ηP)), q(x) the
/// closed form, at every step; the errors fall as the elements at the stick ends shrink.
#[test]
fn bulk_stress_offsets_the_stick_zone_by_a_sigma_over_two_eta_p0() {
    let eta = 0.3;
    let model = elastic(0.5, eta, Coupling::Full);
    let p = 2240.0;
    let hertz = Hertz::new(p, radius_of(&model), model.compliance.y22);
    let a = hertz.half_width;
    let exact = BulkStressCattaneo::new(CattaneoMindlin::new(hertz, eta, p));
    let (q_star, sigma_star) = (0.5 * eta * p, 0.2 * eta * hertz.peak_pressure);
    assert!(sigma_star / hertz.peak_pressure <= q_star / p);
    assert!(exact.holds(q_star, sigma_star));
    let (e, c) = (
        exact.offset(q_star, sigma_star),
        exact.stick_half_width(q_star),
    );
    assert!((e / a - 0.1).abs() < 1e-12);
    let mut errors = Vec::new();
    for stick in [4e-3, 2e-3, 1e-3] {
        let solver = Solver::new(&model, graded_at(a, [e - c, e + c], stick), Options::default());
        let mesh = solver.mesh().clone();
        let (mut s, _) = solver
            .step(&GeneralState::unloaded(mesh.clone()), loads(p, 0.0))
            .unwrap();
        let mut worst = (0.0f64, 0.0f64, 0.0f64);
        for k in 1..=4 {
            let f = k as f64 / 4.0;
            let (q, sigma) = (f * q_star, f * sigma_star);
            s = solver.step(&s, with_bulk(p, q, sigma)).unwrap().0;
            use ElementState::*;
            let zones = s.zones();
            let kinds: Vec<ElementState> = zones.iter().map(|z| z.0).collect();
            assert_eq!(kinds, [Exterior, SlipNegative, Stick, SlipNegative, Exterior]);
            let (lo, hi) = (zones[2].1, zones[2].2);
            let (e_k, c_k) = (exact.offset(q, sigma), exact.stick_half_width(q));
            // Each stick end lies within the element at the end of the stick run or the next.
            assert!((lo - (e_k - c_k)).abs() <= 1.05 * mesh.width_at(e_k - c_k));
            assert!((hi - (e_k + c_k)).abs() <= 1.05 * mesh.width_at(e_k + c_k));
            let l1 = (0..mesh.len())
                .map(|i| {
                    let m = element_mean(&mesh, i, |x| exact.traction(q, sigma, x));
                    (s.shear[i] - m).abs() * mesh.width(i)
                })
                .sum::<f64>()
                / q;
            // The mesh is refined at the final stick ends: measure the error there.
            worst = (
                (0.5 * (lo + hi) - e_k).abs() / a,
                (0.5 * (hi - lo) - c_k).abs() / a,
                l1,
            );
        }
        eprintln!(
            "bulk stress, stick {stick:.0e} ({} el.): |Δe|/a = {:.2e}, |Δc|/a = {:.2e}, ‖Δq‖₁/Q* = {:.2e}",
            mesh.len(),
            worst.0,
            worst.1,
            worst.2
        );
        errors.push(worst);
    }
    // Measured at Q*, stick-end elements 4e−3, 2e−3, 1e−3 a: |Δe|/a = 1.1e−3, 6.6e−4, 3.7e−4
    // (first order, each stick end within its element); |Δc|/a = 5.6e−4, 6.0e−5, 2.5e−4 (within
    // an element, no trend: the two end errors cancel by chance); ‖Δq‖₁/Q* = 1.35e−4, 8.1e−5,
    // 5.1e−5 (as for Cattaneo–Mindlin without σB: 9.6e−5, 5.6e−5, 4.5e−5).
    for w in errors.windows(2) {
        assert!(w[1].0 < w[0].0 / 1.4 && w[1].2 < w[0].2 / 1.2, "{errors:?}");
    }
    let last = errors[2];
    assert!(last.0 < 6e-4 && last.1 < 1.05e-3 && last.2 < 7e-5, "{errors:?}");
}

/// The uncoupled cylinder (ν = 0.5, η = 0.3) pressed to P = 2240 N/m on a mesh graded at
/// the ends (4e−3 a): P, the solver and the pressed state.
fn pressed() -> (f64, Solver, GeneralState) {
    let model = elastic(0.5, 0.3, Coupling::Full);
    let p = 2240.0;
    let a = Hertz::new(p, radius_of(&model), model.compliance.y22).half_width;
    let solver = Solver::new(&model, graded_stick(a, 4e-3), Options::default());
    let (s0, _) = solver
        .step(&GeneralState::unloaded(solver.mesh().clone()), loads(p, 0.0))
        .unwrap();
    (p, solver, s0)
}

/// A zero bulk stress is no change: a step with `bulk_stress = 0.0` gives the state of a step
/// without it to the bit, and the state serialises without the field (old checkpoints read).
#[test]
fn zero_bulk_stress_changes_nothing() {
    let (p, solver, s0) = pressed();
    let (plain, _) = solver.step(&s0, loads(p, 0.1 * p)).unwrap();
    let (zero, _) = solver.step(&s0, with_bulk(p, 0.1 * p, 0.0)).unwrap();
    assert_eq!(plain, zero);
    let json = serde_json::to_string(&zero).unwrap();
    assert!(!json.contains("bulk_stress"));
    let (stressed, _) = solver.step(&s0, with_bulk(p, 0.1 * p, 1e6)).unwrap();
    let json = serde_json::to_string(&stressed).unwrap();
    let back: GeneralState = serde_json::from_str(&json).unwrap();
    assert_eq!(back, stressed);
    assert_ne!(stressed.shear, plain.shear);
}

/// The surface stress σxx0 (seed eqs. 64–65) includes σB: the same tractions with and without
/// the bulk stress differ in σxx0 by σB exactly, inside and outside the contact, and not in Dx0.
#[test]
fn surface_sigma_xx_includes_the_bulk_stress() {
    let (p, solver, s0) = pressed();
    let model = elastic(0.5, 0.3, Coupling::Full);
    let a = Hertz::new(p, radius_of(&model), model.compliance.y22).half_width;
    let sigma = 3e6;
    let (stressed, _) = solver.step(&s0, with_bulk(p, 0.1 * p, sigma)).unwrap();
    let mut bare = stressed.clone();
    bare.loads.bulk_stress = 0.0;
    for x in [-1.05 * a, -0.5 * a, 0.013 * a, 0.7 * a, 1.08 * a] {
        let (with, without) = (
            solver.surface_point(&model, &stressed, x),
            solver.surface_point(&model, &bare, x),
        );
        assert!((with.sigma_xx - without.sigma_xx - sigma).abs() < 1e-9 * sigma);
        assert!((with.d_x - without.d_x).abs() <= 0.0);
    }
}
