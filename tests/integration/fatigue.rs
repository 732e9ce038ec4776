//! The fretting-fatigue indicators ([`fretsim::fatigue`]) on the steady Mindlin–Deresiewicz
//! cycle of the uncoupled cylinder (μ = 27.3 GPa, ν = 0.5, R = 10 mm, η = 0.3,
//! P = 2240 N/m, Q between ±Q* = ±½ηP), against closed forms.
//!
//! The slip amplitude. Unloading from +Q* to −Q* changes the traction by
//! `Δq = −2ηp0 [√(1 − x²/a²) − (c/a)√(1 − x²/c²)]` (the second term on |x| < c), with the
//! stick half-width c = a√(1 − Q*/(ηP)) of the extreme (Mindlin–Deresiewicz: the reverse
//! stick zone at −Q* is c again). The surface strain of the half-plane (ν = 0.5: no pressure
//! term) is `∂ux/∂x = (y11/π) ⨍ q(s)/(s − x) ds`, and
//! `(1/π) ⨍ √(b² − s²)/(s − x) ds = −x + sign(x)√(x² − b²)·[|x| > b]`, so that on c < |x| < a
//! `Δε = 2ηp0 y11 sign(x) √(x² − c²)/a`, and the slip (zero on the stick zone)
//! `s(x) = ∫_c^|x| Δε = (ηp0 y11/a)[|x|√(x² − c²) − c² ln((|x| + √(x² − c²))/c)]`. Each point
//! slips one way over the half-cycle (from the moment the reverse slip zone reaches it) and
//! back over the other, so `δslip(x) = |s(x)|/2`, largest at the contact ends.
//!
//! σxx0 at the extremes: McEwen's surface stress, `p0 N(x/a) ± ηp0 [T(x/a) − (c/a) T(x/c)]`
//! (`analytical::mcewen` at z = 0, the Cattaneo–Mindlin traction as the difference of two
//! sliding ones), and σmax the larger of the two.

use fretsim::analytical::mcewen;
use fretsim::history::NoObserver;

/// `scenarios/fretting_fatigue.json`: the cycle of the module docs, 20 steps a segment,
/// 800 grid points.
fn scenario_text() -> String {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/fretting_fatigue.json");
    std::fs::read_to_string(path).unwrap()
}

struct Cycle {
    solution: fretsim::io::Solution,
    /// a, p0, η, c, y11.
    a: f64,
    p0: f64,
    eta: f64,
    c: f64,
    y11: f64,
}

fn steady_cycle() -> Cycle {
    cycle_of(&scenario_text())
}

fn cycle_of(text: &str) -> Cycle {
    let raw = fretsim::scenario::parse(text, std::path::Path::new("<test>")).unwrap();
    let scenario = fretsim::scenario::validate(raw).unwrap();
    let solution = fretsim::io::solve(&scenario, &mut NoObserver).unwrap();
    let n = &solution.summary.normal_loading;
    let (a, p0) = (n.half_width, n.peak_pressure);
    let y11 = scenario.model.compliance.y11;
    Cycle {
        solution,
        a,
        p0,
        eta: 0.3,
        c: a * 0.5f64.sqrt(),
        y11,
    }
}

impl Cycle {
    /// The closed-form δslip(x).
    fn slip_amplitude(&self, x: f64) -> f64 {
        let (x, c) = (x.abs(), self.c);
        if x <= c || x >= self.a {
            return 0.0;
        }
        let root = (x * x - c * c).sqrt();
        let s = self.eta * self.p0 * self.y11 / self.a * (x * root - c * c * ((x + root) / c).ln());
        0.5 * s.abs()
    }

    /// The largest deviation of a profile's δslip from [`Self::slip_amplitude`] over its grid,
    /// relative to the closed form's value at the contact end.
    fn slip_error(&self, profile: &fretsim::fatigue::FatigueProfile) -> f64 {
        let edge = self.slip_amplitude(self.a * (1.0 - 1e-12));
        profile
            .points
            .iter()
            .map(|p| (p.slip_amplitude - self.slip_amplitude(p.x)).abs() / edge)
            .fold(0.0, f64::max)
    }

    /// McEwen's surface σxx0 at the extreme ±Q* (`sign` = ±1).
    fn sigma(&self, x: f64, sign: f64) -> f64 {
        let (a, c) = (self.a, self.c);
        let normal = mcewen(x / a, 0.0).0[0];
        let slide = mcewen(x / a, 0.0).1[0] - c / a * mcewen(x / c, 0.0).1[0];
        self.p0 * normal + sign * self.eta * self.p0 * slide
    }
}

/// δslip(x) of the last cycle against Mindlin–Deresiewicz's, its largest value at the contact
/// end, and the cycles' `max_local_slip`.
#[test]
fn mindlin_deresiewicz_local_slip_amplitude() {
    let cycle = steady_cycle();
    let profile = cycle.solution.fatigue.as_ref().expect("a complete cycle");
    let edge = cycle.slip_amplitude(cycle.a * (1.0 - 1e-12));
    // The y11 of plane strain at ν = 0.5: (1 − ν)/μ.
    assert!((cycle.y11.abs() - 0.5 / 27.3e9).abs() < 1e-12 * cycle.y11.abs());
    let worst = cycle.slip_error(profile);
    let top = profile.extreme(|p| p.slip_amplitude);
    let grid_edge = profile
        .points
        .iter()
        .filter(|p| p.x.abs() < cycle.a)
        .map(|p| cycle.slip_amplitude(p.x))
        .fold(0.0, f64::max);
    println!(
        "δslip within {worst:.2e} of the edge value {edge:.4e} m; largest {:.6e} m at x/a = {} \
         (closed form on the grid {grid_edge:.6e} m)",
        top.value, top.x_over_a
    );
    // Measured 8.9e−15: the spectral solution and the slip zone's graded rule are exact to
    // round-off on this cycle.
    assert!(worst < 1e-12, "{worst:e}");
    assert!(
        top.x_over_a.abs() > 0.99,
        "at the contact end: {}",
        top.x_over_a
    );
    assert!((top.value - grid_edge).abs() < 1e-12 * edge);
    let rows = &cycle.solution.cycles;
    assert_eq!(rows.len(), 2);
    for row in rows {
        let m = row.max_local_slip.expect("set by the run");
        assert!(
            (m - grid_edge).abs() < 1e-12 * edge,
            "cycle {}: {m:e}",
            row.cycle
        );
    }
}

/// σmax and σmin of the last cycle against McEwen's surface stress at the two extremes.
#[test]
fn mcewen_surface_stress_extremes_of_the_cycle() {
    let cycle = steady_cycle();
    let profile = cycle.solution.fatigue.as_ref().expect("a complete cycle");
    let scale = cycle.p0;
    let (mut worst_max, mut worst_min) = (0.0f64, 0.0f64);
    for p in &profile.points {
        let (plus, minus) = (cycle.sigma(p.x, 1.0), cycle.sigma(p.x, -1.0));
        worst_max = worst_max.max((p.sigma_max - plus.max(minus)).abs() / scale);
        worst_min = worst_min.max((p.sigma_min - plus.min(minus)).abs() / scale);
    }
    println!("σmax within {worst_max:.2e} p0, σmin within {worst_min:.2e} p0");
    // Measured 9.1e−15 and 1.1e−14.
    assert!(
        worst_max < 1e-12 && worst_min < 1e-12,
        "{worst_max:e} {worst_min:e}"
    );
}

/// Ruiz's F2 and SWT: their largest values over the grid, computed here from the closed forms
/// (σmax from McEwen, τ = ηp in the slip zones, δslip from Mindlin–Deresiewicz, the strain
/// amplitude from σxx0 = −p + 4μ ε of plane strain at ν = 0.5, so Δε = Δσxx0/(4μ) at constant
/// p), against the run's, which it takes from the accumulated extremes.
#[test]
fn ruiz_and_swt_maxima_from_the_closed_forms() {
    let cycle = steady_cycle();
    let profile = cycle.solution.fatigue.as_ref().expect("a complete cycle");
    let mu = 27.3e9;
    let hertz = |x: f64| cycle.p0 * (1.0 - (x / cycle.a).powi(2)).max(0.0).sqrt();
    let (mut f2, mut swt) = ((0.0f64, 0.0), (0.0f64, 0.0));
    for p in &profile.points {
        let (plus, minus) = (cycle.sigma(p.x, 1.0), cycle.sigma(p.x, -1.0));
        let tension = plus.max(minus).max(0.0);
        let here = tension * cycle.eta * hertz(p.x) * cycle.slip_amplitude(p.x);
        if here > f2.0 {
            f2 = (here, p.x);
        }
        // p is the same at both extremes: Δε = Δσ/(4μ).
        let strain_amplitude = 0.5 * (plus - minus).abs() / (4.0 * mu);
        if tension * strain_amplitude > swt.0 {
            swt = (tension * strain_amplitude, p.x);
        }
    }
    let (run_f2, run_swt) = (profile.extreme(|p| p.ruiz_f2), profile.extreme(|p| p.swt));
    println!(
        "F2 {:.6e} at x = {:.4e} (closed form {:.6e} at {:.4e}); SWT {:.6e} at {:.4e} \
         (closed form {:.6e} at {:.4e})",
        run_f2.value, run_f2.x, f2.0, f2.1, run_swt.value, run_swt.x, swt.0, swt.1
    );
    let (e_f2, e_swt) = (
        (run_f2.value - f2.0).abs() / f2.0,
        (run_swt.value - swt.0).abs() / swt.0,
    );
    println!("relative errors: F2 {e_f2:.2e}, SWT {e_swt:.2e}");
    // Measured 3.2e−14 and 0 (round-off: the spectral solution is exact here).
    assert!(e_f2 < 1e-12 && e_swt < 1e-12, "{e_f2:e} {e_swt:e}");
    // The same place, up to the symmetry x → −x of the two contact ends (equal values there
    // but for the rounding).
    let same = |x: f64, y: f64| (x.abs() - y.abs()).abs() < 1e-9 * cycle.a;
    assert!(same(run_f2.x, f2.1) && same(run_swt.x, swt.1));
}

/// The general element solver's slip (the mean slip of the element holding each grid point)
/// against Mindlin–Deresiewicz's δslip, within a tolerance set by its element size, and the
/// largest at the contact end.
#[test]
fn mindlin_deresiewicz_local_slip_amplitude_by_the_general_solver() {
    let text = scenario_text().replace(
        r#""output""#,
        r#""numerics": { "solver": "general" }, "output""#,
    );
    let cycle = cycle_of(&text);
    let profile = cycle.solution.fatigue.as_ref().expect("a complete cycle");
    let edge = cycle.slip_amplitude(cycle.a * (1.0 - 1e-12));
    let worst = cycle.slip_error(profile);
    let top = profile.extreme(|p| p.slip_amplitude);
    println!(
        "general solver: δslip within {worst:.2e} of the edge value; largest {:.6e} m at x/a = {}",
        top.value, top.x_over_a
    );
    // Measured 1.1e−2: a grid point takes its element's mean slip, from up to half an element
    // (3e−3 a inside, `numerics.general_element_size`) away, where δslip changes by up to
    // about 4 δslip(a)/a per unit length near the contact end.
    assert!(worst < 2e-2, "{worst:e}");
    assert!((top.value / edge - 1.0).abs() < 2e-2);
    assert!(
        top.x_over_a.abs() > 0.99,
        "at the contact end: {}",
        top.x_over_a
    );
}

/// The in-plane electric field under a conducting punch: the electrode holds the whole contact
/// at one potential, so `Ex = −∂φ/∂x = 0` there at every instant, friction or not, while
/// `Dx0 = −(e15/c44)q` is not zero. On the default PZT-4 history (conducting, Γ = 6e−7 C/m,
/// ±½ηP, M = 64) the range of Ex over the last cycle, recovered from Dx0 and q through eq.
/// (65), is therefore zero at the grid points that stay inside the contact (|x| < 0.8 a) up to
/// the discretisation. Measured, against its largest value outside the contact: 5.8e−4 with
/// the spectral solver taking every step, 1.9e−3 under `auto` (a few steps by the general
/// solver, whose piecewise-constant elements give 2.2e−3 alone); the range of Dx0 inside is
/// 0.19 of its largest.
#[test]
fn a_conducting_punch_holds_the_in_plane_field_at_zero_over_its_contact() {
    for (solver, bound) in [("spectral", 1e-3), ("auto", 3e-3)] {
        let mut raw = fretsim::scenario::default_scenario().raw;
        raw.numerics.solver = serde_json::from_value(serde_json::json!(solver)).unwrap();
        let scenario = fretsim::scenario::validate(raw).unwrap();
        let solution = fretsim::io::solve(&scenario, &mut NoObserver).unwrap();
        let profile = solution.fatigue.as_ref().expect("a complete cycle");
        let a = solution.summary.normal_loading.half_width;
        let (inside, outside): (Vec<&fretsim::fatigue::PointIndicators>, Vec<_>) =
            profile.points.iter().partition(|p| p.x.abs() < 0.8 * a);
        let most = |points: &[&fretsim::fatigue::PointIndicators],
                    f: fn(&fretsim::fatigue::PointIndicators) -> f64| {
            points.iter().map(|p| f(p)).fold(0.0, f64::max)
        };
        let (e_in, e_out) = (
            most(&inside, |p| p.e_x_range),
            most(&outside, |p| p.e_x_range),
        );
        let d_in = most(&inside, |p| p.d_x_range);
        let d_all = profile
            .points
            .iter()
            .map(|p| p.d_x_range)
            .fold(0.0, f64::max);
        assert!(
            e_in <= bound * e_out,
            "{solver}: {e_in:e} against {e_out:e}"
        );
        assert!(d_in > 0.1 * d_all, "{solver}: ΔDx0 {d_in:e} of {d_all:e}");
    }
}
