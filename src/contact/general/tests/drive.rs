//! A prescribed punch displacement ([`Drive::Displacement`]) against Mindlin's closed forms.

use super::*;

/// Displacement control (`Drive::Displacement`) of the uncoupled contact (ν = ½): the step to
/// the δx of a load-controlled step to Q* = ηP/2 is that step (the two programmes share their
/// KKT point); δx from Mindlin's closed form gives Q*; beyond the displacement at which Q
/// reaches ηP every element slips and Q = ηP (the Coulomb plateau); a reversal from there
/// follows the Mindlin–Deresiewicz branch of Q* = ηP.
#[test]
fn displacement_control_mindlin_branches_and_the_coulomb_plateau() {
    let eta = 0.3;
    let model = elastic(0.5, eta, Coupling::Full);
    let p = 2240.0;
    let hertz = Hertz::new(p, radius_of(&model), model.compliance.y22);
    let a = hertz.half_width;
    let (y11, d) = (model.compliance.y11, model.reference_distance);
    let exact = CattaneoMindlin::new(hertz, eta, p);
    let limit = eta * p;
    let solver = Solver::new(&model, graded_stick(a, 1e-3), Options::default());
    let mesh = solver.mesh().clone();
    let (s0, _) = solver
        .step(&GeneralState::unloaded(mesh.clone()), loads(p, 0.0))
        .unwrap();
    let at = |delta: f64| Drive::Displacement(s0.shift + delta);

    // The same state by either drive.
    let (by_load, _) = solver.step(&s0, loads(p, 0.5 * limit)).unwrap();
    let (by_shift, _) = solver
        .step_with(&s0, loads(p, 0.0), Drive::Displacement(by_load.shift))
        .unwrap();
    let dq = by_load
        .shear
        .iter()
        .zip(&by_shift.shear)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    assert!(dq < 1e-9 * limit / a, "{dq}");
    assert_eq!(by_load.codes, by_shift.codes);
    assert!((by_shift.loads.tangential - 0.5 * limit).abs() < 1e-9 * limit);

    // Mindlin's δ(Q*) gives Q*: measured ΔQ/ηP = 1.6e−8 (δ integrates q over the contact, so
    // the stick-end resolution enters at second order).
    let delta_half = exact.loading_displacement(0.5 * limit, y11, d);
    let (s1, _) = solver.step_with(&s0, loads(p, 0.0), at(delta_half)).unwrap();
    let error = (s1.loads.tangential - 0.5 * limit).abs() / limit;
    eprintln!("Q at Mindlin's δ(ηP/2): ΔQ/ηP = {error:.2e}");
    assert!(error < 1e-7, "{error}");

    // Gross slip beyond δ_g = δ(ηP): Q = ηP, no element sticks, and every element slips by
    // the excess of the punch displacement over the step's.
    let delta_g = exact.loading_displacement(limit, y11, d);
    let (s2, _) = solver.step_with(&s1, loads(p, 0.0), at(1.5 * delta_g)).unwrap();
    assert!((s2.loads.tangential - limit).abs() < 1e-12 * limit);
    assert!(!s2.codes.contains(&ElementState::Stick));
    let (s3, _) = solver.step_with(&s2, loads(p, 0.0), at(1.6 * delta_g)).unwrap();
    assert!((s3.loads.tangential - limit).abs() < 1e-12 * limit);
    for (i, &code) in s3.codes.iter().enumerate() {
        if code != ElementState::Exterior {
            assert_eq!(code, ElementState::SlipNegative);
            // The surface does not move under constant tractions: the slip is −Δδx.
            assert!((s3.slip[i] + 0.1 * delta_g).abs() < 1e-9 * delta_g, "{}", s3.slip[i]);
        }
    }

    // Back along the Mindlin–Deresiewicz branch of Q* = ηP (Masing), measured from the plateau's
    // turning point: δ(Q) = δ* − 2δ_load((ηP − Q)/2).
    let delta_star = 1.6 * delta_g;
    let mut s = s3;
    let mut worst: f64 = 0.0;
    for k in 1..=8 {
        let q = limit * (1.0 - 0.25 * k as f64);
        let target = delta_star - 2.0 * exact.loading_displacement(0.5 * (limit - q), y11, d);
        s = solver.step_with(&s, loads(p, 0.0), at(target)).unwrap().0;
        worst = worst.max((s.loads.tangential - q).abs() / limit);
    }
    // The last point, Q = −ηP, is the onset of reversed gross slip. Measured 9.3e−7.
    eprintln!("Mindlin–Deresiewicz branch from the plateau: max ΔQ/ηP = {worst:.2e}");
    assert!(worst < 3e-6, "{worst}");
}
