//! The slip that a change of the conducting punch's charge drives at the contact ends, as the
//! mesh is refined.

use super::*;

/// A charge history at fixed P and Q = 0 (PZT-4, conducting punch, Goodman's approximation):
/// the contact pressed frictionlessly with Γ = 2e−7 C/m (so q = 0, whatever the mesh), then,
/// with η = 0.3, Γ raised to 4e−7 C/m in ten steps on the same mesh. `h` scales every element
/// size of the mesh (`graded(a, 1e−3 h, 1e−2 h)`). Returns the stick ratio at 4e−7 and the
/// friction work of the charge steps.
fn charge_history_on(h: f64) -> (f64, f64) {
    let (p, radius) = (2000.0, 0.06);
    let model = |friction| {
        pzt4(radius, friction, Electrode::ConductingCharge { charge: 2e-7 })
            .with_coupling(Coupling::Goodman)
    };
    let a = Hertz::new(p, radius, model(0.3).compliance.pressure_compliance()).half_width;
    let mesh = graded(a, 1e-3 * h, 1e-2 * h);
    let at = |electric: f64| Loads {
        normal: p,
        tangential: 0.0,
        electric,
        bulk_stress: 0.0,
    };
    let frictionless = Solver::new(&model(0.0), mesh.clone(), Options::default());
    let mut s = frictionless
        .step(&GeneralState::unloaded(mesh.clone()), at(2e-7))
        .unwrap()
        .0;
    let solver = Solver::new(&model(0.3), mesh, Options::default());
    let mut work = 0.0;
    for k in 1..=10 {
        let (t, _) = solver.step(&s, at(2e-7 * (1.0 + 0.1 * k as f64))).unwrap();
        work -= (0..t.mesh.len())
            .map(|i| t.mesh.width(i) * 0.5 * (s.shear[i] + t.shear[i]) * t.slip[i])
            .sum::<f64>();
        s = t;
    }
    let (lo, hi) = s.contact_extent().unwrap();
    (s.length_of(ElementState::Stick) / (hi - lo), work)
}

/// The slip that a change of the punch's charge drives at the contact ends (issue "Load paths
/// beyond the paper", item 4: in the paper's model the pressure of a conducting punch does not
/// depend on Γ, while the change of g strains the surface, `∂ux/∂x ∋ −w13 g`, and the ends
/// slip), converging as the mesh is refined: every element size scaled by h = 4 … 1/8.
///
/// Measured: c/a = 0.802862, 0.814149, 0.809878, 0.809939, 0.809970, 0.809985 and the
/// friction work 1.27128, 1.27544, 1.27574, 1.275189, 1.275175, 1.275163 (×1e−8 J/m). From
/// h = 1 on the stick ratio converges at first order (changes 6.1e−5, 3.1e−5, 1.5e−5, each
/// about half the one before: the stick end is resolved to the element size there) and the
/// work to 1e−5 of itself (changes −4.3e−4, −1.1e−5, −9.7e−6). Started from a frictional
/// normal loading instead (P and Γ together in steps of 2 % of the width), the same meshes
/// scatter by ±3e−3 in c/a and ±1.5 % in the work: the normal loading's own step error,
/// which the mesh does not refine.
#[test]
fn charge_history_converges_as_the_mesh_is_refined() {
    let results: Vec<(f64, f64)> = [4.0, 2.0, 1.0, 0.5, 0.25, 0.125]
        .iter()
        .map(|&h| charge_history_on(h))
        .collect();
    eprintln!("charge history, h = 4 … 1/8: (c/a, friction work) = {results:?}");
    let change = |k: usize, f: fn(&(f64, f64)) -> f64| f(&results[k + 1]) - f(&results[k]);
    let ratio = |r: &(f64, f64)| r.0;
    for k in 3..5 {
        let (before, now) = (change(k - 1, ratio), change(k, ratio));
        assert!(
            now.abs() < 0.7 * before.abs() && now.abs() > 0.3 * before.abs(),
            "c/a changes {before:e}, {now:e}"
        );
    }
    let work = |r: &(f64, f64)| r.1;
    for k in 3..5 {
        assert!(change(k, work).abs() < 2e-5 * results[5].1, "{results:?}");
    }
    // The ends slip: the stick zone is well inside the contact.
    assert!(results[5].0 < 0.85);
}
